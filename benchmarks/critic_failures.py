"""Critics against the oracle on a balanced set of successes and injected silent failures.

For every subtask of the chosen goals and every seed, the goal's plan runs up to that subtask in a
V-CAGE scene (context-aware placement, checked scene, 4 distractors): once as planned, and once for
each fault drawn for it from :mod:`vcage.skills.faults` (release high/early/late or never, off
target, on an edge, wrong object, too light, hovering, beside the button, knocked over). The fault
changes only what the robot does; the outcome is simulated in MuJoCo, and the label is the
oracle's afterwards: an injected fault that still succeeded counts as a success, one that raised a
skill error (no silent failure) is left out, and so is a sample whose earlier subtasks failed.

Each critic judges the views it would get in a run (before, during and after the subtask). Printed
per skill family and per fault: the sample's composition (successes, failures, distinct scenes),
balanced accuracy, false-accept rate (failures accepted) and false-reject rate (successes
rejected); "n/a" where a denominator is empty.

    nice .venv/bin/python benchmarks/critic_failures.py --seeds 2 --workers 2 --cache /tmp/cf

The VLM critic judges the same samples with ``--vlm-tape FILE``: it talks to a local
OpenAI-compatible endpoint (``benchmarks/vlm_tape.py``) that, with ``--vlm-record``, forwards each
question to the model named by ``VCAGE_VLM_BASE_URL``, ``VCAGE_VLM_MODEL`` and ``VCAGE_VLM_API_KEY``
and keeps its answers on the tape, and otherwise answers from the tape, so a measurement made once
against a real model can be re-printed (and audited answer by answer) without it:

    VCAGE_VLM_BASE_URL=https://... VCAGE_VLM_MODEL=... VCAGE_VLM_API_KEY=... \
        .venv/bin/python benchmarks/critic_failures.py --seeds 5 --first-seed 5 --faults-per-seed 3 \
        --cache DIR --vlm-tape vlm.jsonl --vlm-record

``--cache DIR`` stores every sample's observation (and re-uses it on the next run, so a changed
critic is re-judged without simulating again; a directory filled by code that has changed outside
``vcage/critics`` since is refused, see ``obs_cache.py``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import time
from collections.abc import Iterable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core

import numpy as np  # noqa: E402

import results  # noqa: E402
from obs_cache import cached, open_cache  # noqa: E402
from vcage.backends import BackendConfig  # noqa: E402
from vcage.critics import CriticConfig, Observation, Recorder, Verdict, make_critic  # noqa: E402
from vcage.critics.base import View  # noqa: E402
from vcage.critics.vlm import ENV_PREFIX as VLM_ENV  # noqa: E402
from vcage.errors import VcageError  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.episode import Timing  # noqa: E402
from vcage.pipeline.plan_layout import plan_layout  # noqa: E402
from vcage.pipeline.rollout import run_plan  # noqa: E402
from vcage.planning import make_planner  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402
from vcage.planning.schema import Plan  # noqa: E402
from vcage.scene.instantiate import Instantiator  # noqa: E402
from vcage.sim.render import Renderer  # noqa: E402
from vcage.skills.base import Skills  # noqa: E402
from vcage.skills.faults import FaultConfig, FaultInjector, faults_for  # noqa: E402
from vcage.skills.playback import Player  # noqa: E402
from vcage.skills.reachability import reach_map  # noqa: E402
from vcage.tasks.verifier import Verifier  # noqa: E402
from vlm_tape import Tape, tape_model  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk", "set_the_table",
                 "build_a_tower", "sort_blocks_by_colour")
CRITICS = ("image", "oracle")


@dataclass
class Sample:
    goal: str
    subtask: int
    skill: str
    fault: str | None  # None: run as planned
    seed: int
    scene: str  # hash of the instantiated scene (its spec)
    success: bool  # the oracle's label of the subtask
    obs: Observation


def _plan(goal: str) -> Plan:
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    return make_planner("offline").plan(phrase)


def rollout(goal: str, index: int, seed: int, fault: str | None) -> Sample | str:
    """Run ``goal``'s plan up to subtask ``index`` (with ``fault`` injected into it); the sample of
    that subtask, or why there is none."""
    full = _plan(goal)
    plan = full.model_copy(update={"subtasks": full.subtasks[:index + 1]})
    cfg = GenerateConfig()
    rng = np.random.default_rng(seed)
    layout = plan_layout(full, rng, cfg.randomization, cfg.scene.clutter)  # one scene per goal and seed
    inst = Instantiator(cfg.scene, cfg.sim, reach_map())
    try:
        spec, stats = inst.place(layout, rng)
        instance = inst.realize(spec, stats)
    except Exception as exc:  # noqa: BLE001 - a scene that cannot be made gives no sample
        return f"scene: {type(exc).__name__}"
    if not instance.valid:
        return "scene: invalid"
    world, sub = instance.world, plan.subtasks[index]
    injector = None
    if fault is not None:
        occurrence = sum(s.skill == sub.skill for s in plan.subtasks[:index])
        injector = FaultInjector(FaultConfig(fault, sub.skill, occurrence, seed))
    skills = Skills(world, Player(world, record_states=True), fault=injector)
    keep = Recorder()
    with Renderer(world, *cfg.render.critic_size, cfg.render.mesh_detail) as renderer:
        verifier = Verifier(world, plan.subtasks, keep, renderer, skills.player.recording, Timing())
        result = run_plan(world, plan, skills, verifier)
    outcomes = result.outcomes
    if len(outcomes) <= index or outcomes[index].skill_error is not None:
        return "skill error"
    if not all(o.oracle_success for o in outcomes[:index]):
        return "an earlier subtask failed"
    if injector is not None and not injector.applied:
        return "fault not applicable"
    scene = hashlib.sha1(json.dumps(spec.to_dict(), sort_keys=True, default=str).encode()).hexdigest()[:12]
    return Sample(goal, index, sub.skill, fault, seed, scene, outcomes[index].oracle_success,
                  keep.seen[index])


def _job(job: tuple[str, int, int, str | None, str | None]) -> Sample | str:
    goal, index, seed, fault, cache = job
    path = Path(cache) / f"{goal}-{index}-{seed}-{fault or 'none'}.pkl.gz" if cache else None
    return cached(path, lambda: rollout(goal, index, seed, fault))


def jobs(goals: Iterable[str], seeds: int, faults_per_seed: int, cache: str | None, first_seed: int = 0
         ) -> list[tuple[str, int, int, str | None, str | None]]:
    out: list[tuple[str, int, int, str | None, str | None]] = []
    for goal in goals:
        for i, sub in enumerate(_plan(goal).subtasks):
            names = faults_for(sub.skill)
            for seed in range(first_seed, first_seed + seeds):
                out.append((goal, i, seed, None, cache))
                # rotate through the faults, seed by seed (each once per seed: a skill with one fault
                # gives one faulty rollout per seed, not the same one twice)
                picked = [names[(seed * faults_per_seed + k + i) % len(names)]
                          for k in range(faults_per_seed if names else 0)]
                out.extend((goal, i, seed, name, cache) for name in dict.fromkeys(picked))
    return out


# -- figures ------------------------------------------------------------------------------------------

def _pct(num: int, den: int) -> str:
    return f"{num / den:6.1%}" if den else "   n/a"


def row(name: str, samples: list[Sample], accepts: list[bool]) -> str:
    succ = [a for s, a in zip(samples, accepts, strict=True) if s.success]
    fail = [a for s, a in zip(samples, accepts, strict=True) if not s.success]
    tpr, tnr = (sum(succ), len(succ)), (sum(not a for a in fail), len(fail))
    bal = (f"{(tpr[0] / tpr[1] + tnr[0] / tnr[1]) / 2:6.1%}" if tpr[1] and tnr[1] else "   n/a")
    scenes = len({(s.goal, s.scene) for s in samples})
    false_accept, false_reject = _pct(sum(fail), len(fail)), _pct(len(succ) - sum(succ), len(succ))
    return (f"{name:28s} {len(succ):5d} {len(fail):5d} {scenes:6d}  {bal:>7s} {false_accept:>7s} "
            f"{false_reject:>7s}")


def rates(samples: list[Sample], accepts: list[bool]) -> dict[str, float]:
    """Balanced accuracy, false-accept and false-reject rates (fractions) of ``accepts``."""
    succ = [a for s, a in zip(samples, accepts, strict=True) if s.success]
    fail = [a for s, a in zip(samples, accepts, strict=True) if not s.success]
    far, frr = sum(fail) / len(fail), (len(succ) - sum(succ)) / len(succ)
    return {"balanced": ((1 - frr) + (1 - far)) / 2, "false_accepts": far, "false_rejects": frr}


HEAD = f"{'':28s} {'succ':>5s} {'fail':>5s} {'scenes':>6s}  {'bal.acc':>7s} {'FA':>7s} {'FR':>7s}"


def report(samples: list[Sample], critic: str, accepts: list[bool]) -> None:
    print(f"\n{critic} critic vs oracle")
    print(HEAD)
    print(row("all", samples, accepts))
    for key, label in ((lambda s: s.skill, "skill"), (lambda s: s.fault or "(as planned)", "fault"),
                       (lambda s: f"{s.goal}#{s.subtask + 1}", "subtask")):
        for value in sorted({key(s) for s in samples}):
            pick = [k for k, s in enumerate(samples) if key(s) == value]
            print(row(f"{label} {value}"[:28], [samples[k] for k in pick], [accepts[k] for k in pick]))


def _same(obs: Observation) -> Observation:
    return obs


def _no_top_depth(obs: Observation) -> Observation:
    """``obs`` without the top view's depth: what the image critic saw before it read press depth."""
    def strip(views: dict[str, View]) -> dict[str, View]:
        return {cam: replace(v, depth=None) if cam == "top" else v for cam, v in views.items()}

    return replace(obs, before=strip(obs.before), during=strip(obs.during), after=strip(obs.after))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=2, help="scenes per subtask (seeds K..K+N-1)")
    parser.add_argument("--first-seed", type=int, default=0, help="K: the first seed (a later K gives a "
                        "set disjoint from one a check was tuned on)")
    parser.add_argument("--faults-per-seed", type=int, default=2)
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cache", default=None, help="directory for the samples' observations")
    parser.add_argument("--show-errors", action="store_true", help="print each misjudged sample")
    parser.add_argument("--vlm-tape", default=None, help="also judge with the VLM critic, through a local "
                        "endpoint that answers from this tape of a model's answers")
    parser.add_argument("--vlm-record", action="store_true", help="with --vlm-tape: ask the model of the "
                        f"{VLM_ENV}_* variables and add its answers to the tape")
    parser.add_argument("--vlm-votes", type=int, default=1, help="questions per judgment (majority)")
    parser.add_argument("--record", action="store_true", help="write the image critic's figures to "
                        "docs/results/critic_failures.json (the results page)")
    args = parser.parse_args()
    if args.vlm_record and not args.vlm_tape:
        parser.error("--vlm-record needs --vlm-tape FILE")
    cache = open_cache(args.cache)
    todo = jobs(args.goals, args.seeds, args.faults_per_seed, str(cache) if cache else None, args.first_seed)
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(_job, todo))
    samples = [r for r in results if isinstance(r, Sample)]
    skipped: dict[str, int] = {}
    for r in results:
        if isinstance(r, str):
            skipped[r] = skipped.get(r, 0) + 1
    injected = [s for s in samples if s.fault is not None]
    bare = sorted({sub.skill for g in args.goals for sub in _plan(g).subtasks if not faults_for(sub.skill)})
    if bare:
        print(f"no faults registered for skill(s) {', '.join(bare)}: their subtasks give successes only")
    print(f"balanced set: goals {', '.join(args.goals)}; {args.seeds} seeds per subtask (from seed "
          f"{args.first_seed}), as planned + "
          f"{args.faults_per_seed} injected faults per seed; {len(todo)} rollouts, {len(samples)} samples "
          f"({sum(s.success for s in samples)} successes, {sum(not s.success for s in samples)} failures; "
          f"{sum(s.success for s in injected)} injected faults still succeeded), "
          f"{len({(s.goal, s.scene) for s in samples})} distinct scenes; left out: {skipped or 'none'}; "
          f"{time.perf_counter() - t0:.0f} s wall")
    print("succ/fail: the oracle's labels; scenes: distinct instantiated scenes; bal.acc: mean of the "
          "accept rate on successes and the reject rate on failures; FA: failures accepted; FR: "
          "successes rejected; n/a: empty denominator")
    variants = [(name, name, _same) for name in CRITICS]
    variants.insert(1, ("image", "image, no top-view depth", _no_top_depth))  # the critic before it had it
    for name, label, seen in variants:
        critic = make_critic(CriticConfig(name))
        verdicts = [critic.judge(seen(s.obs)) for s in samples]
        report(samples, label, [v.accept for v in verdicts])
        if args.show_errors:
            errors(samples, verdicts)
        if args.record and label == "image":
            _record(args, samples, [v.accept for v in verdicts])
    if args.vlm_tape:
        judge_vlm(samples, Path(args.vlm_tape), args.vlm_record, args.vlm_votes, args.show_errors)


def _record(args: argparse.Namespace, samples: list[Sample], accepts: list[bool]) -> None:
    r = rates(samples, accepts)
    succ = sum(s.success for s in samples)
    fails = len(samples) - succ
    fa = sum(a for s, a in zip(samples, accepts, strict=True) if not s.success)
    fr = sum(not a for s, a in zip(samples, accepts, strict=True) if s.success)
    path = results.record(
        "critic_failures", "Image critic on silent failures",
        "Does the offline image critic reject subtasks that silently failed (injected motion faults) and "
        "accept those that succeeded, with the oracle as ground truth?",
        {"balanced accuracy": f"{r['balanced']:.1%}",
         "false accepts (failures accepted)": f"{r['false_accepts']:.1%} ({fa} of {fails})",
         "false rejects (successes rejected)": f"{r['false_rejects']:.1%} ({fr} of {succ})",
         "accepting everything": "50.0% balanced accuracy"},
        f"{succ} successes and {fails} failures (oracle labels), "
        f"{len({(s.goal, s.scene) for s in samples})} distinct scenes of the goals {', '.join(args.goals)}, "
        f"seeds {args.first_seed}-{args.first_seed + args.seeds - 1}, {args.faults_per_seed} injected faults "
        "per seed")
    print(f"recorded in {path}")


def errors(samples: list[Sample], verdicts: list[Verdict]) -> None:
    for s, v in zip(samples, verdicts, strict=True):
        if v.accept != s.success:
            print(f"  {'FA' if v.accept else 'FR'} {s.goal}#{s.subtask + 1} seed {s.seed} "
                  f"{s.fault or '-'}: {v.reason}; oracle {s.obs.oracle}")


def judge_vlm(samples: list[Sample], tape_path: Path, record: bool, votes: int, show_errors: bool) -> None:
    """The VLM critic on ``samples``, through :class:`vlm_tape.Tape` (recording or replaying)."""
    try:
        upstream = BackendConfig.from_env(VLM_ENV) if record else None
    except VcageError as exc:
        raise SystemExit(f"error: {exc} (--vlm-record asks the model those variables name)") from exc
    if upstream is not None and upstream.provider != "openai":
        raise SystemExit(f"error: the tape speaks the OpenAI protocol; {VLM_ENV}_PROVIDER="
                         f"{upstream.provider} is not forwarded (Gemini also serves an OpenAI-compatible "
                         "endpoint)")
    model = upstream.model if upstream is not None else tape_model(tape_path)
    if model is None:
        raise SystemExit(f"error: no answers on the tape {tape_path}: record them with --vlm-record")
    with Tape(tape_path, upstream) as tape:
        critic = make_critic(CriticConfig("vlm", backend=BackendConfig(base_url=tape.base_url, model=model),
                                          votes=votes))
        try:
            critic.preflight()
            verdicts = [critic.judge(s.obs) for s in samples]
        except VcageError as exc:
            raise SystemExit(f"error: the VLM critic could not judge: {exc}") from exc
    malformed = sum(int(v.details.get("malformed", 0)) for v in verdicts)
    report(samples, f"vlm ({model}; {votes} vote(s); answers {'recorded to' if record else 'replayed from'} "
           f"{tape_path.name}; {tape.served} answered, {malformed} malformed)", [v.accept for v in verdicts])
    if show_errors:
        errors(samples, verdicts)


if __name__ == "__main__":
    main()
