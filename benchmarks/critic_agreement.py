"""The image critic against the oracle on hard cases: Vanilla rollouts, judged but never stopped.

In a V-CAGE run few subtasks fail (the scenes are valid), so the critic's agreement there rests on
few negatives. Here every goal runs with naive placement and no scene check (the Vanilla setting,
where most episodes fail), the image critic judges every subtask from the rendered views, and the
rollout continues whatever it says, so each subtask gives one (critic, oracle) pair. Subtasks whose
skill could not plan are left out (no critic is asked about them in a run either). Episode k
uses the seed of the first attempt at episode k in ``vcage_vs_vanilla``'s Vanilla run.

Printed per goal and overall, beside every figure, the sample it rests on: judged subtasks, the
oracle's successes and failures among them, and the distinct scenes they come from; then
agreement, precision and recall of "accept" (as in ``vcage audit``), the share of the oracle's
failures the critic rejected (what keeps them out of a dataset) and balanced accuracy. A figure
whose denominator is empty prints "n/a" (not 0%).

Then the same figures split by how the rollout starts: with the plan's objects clear of every other
object, or with one of them interpenetrating another deeper than 1 mm once the scene settled (the
bound of V-CAGE's scene check; objects resting on one another in a settled scene sink 0.1-0.55 mm).
Naive placement leaves many objects fused into each other (a seal sunk into a phone, a cup into a
bell), and a fused pair moves as one; there the oracle's contact-based verdict reads a state no
physical scene has, and V-CAGE's checked scenes never start so. The overall figure counts both.

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/critic_agreement.py --seeds 10 --workers 2

``--first-seed K`` starts at episode K, for a sample that no threshold was chosen on.

``--mesh-detail full`` renders the critic's views with the robot's meshes as shipped (the default
is the simplified meshes, as in a run).

``--cache DIR`` stores every judged subtask's observation and the oracle's verdict, and how the
rollout started (re-used on the next run, so a changed critic is re-judged in seconds without
simulating again; a directory filled by code that has changed outside ``vcage/critics`` since, or
holding entries of an earlier form, is refused, see ``obs_cache.py``).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core

from obs_cache import cached, fingerprint, open_cache  # noqa: E402
from vcage.config import MESH_DETAILS, RenderConfig  # noqa: E402
from vcage.critics import CriticConfig, Observation, Recorder, make_critic  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.episode import attempt  # noqa: E402
from vcage.planning import make_planner  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402
from vcage.scene.stability import StabilityConfig  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk", "set_the_table",
                 "build_a_tower", "sort_blocks_by_colour")


Judged = tuple[str, Observation, bool, str, str]  # scene, observation, oracle success, where, oracle
Episode = tuple[float, list[Judged]]  # how deep the plan's objects started fused (Attempt.fused; m), judged
Row = tuple[str, str, bool, bool, str, bool]  # goal, scene, critic accepts, oracle success, why, fused
FUSED = StabilityConfig().penetration  # deeper than this counts as interpenetration (the scene check's bound)
ENTRIES = "episode-v2"  # what a cache entry holds (:data:`Episode`); part of the cache's stamp


def _rollout(goal: str, episode: int, mesh_detail: str) -> Episode:
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    plan = make_planner("offline").plan(phrase)
    # episode k: the seed of the Vanilla run's episode k
    cfg = GenerateConfig.vanilla(seed=0, render=RenderConfig(mesh_detail=mesh_detail))
    recorder = Recorder(make_critic(CriticConfig("image")).needs_views)
    result = attempt(plan, cfg.episode_seed(episode, 0), cfg, recorder)
    if result.rollout is None:
        return 0.0, []
    scene = hashlib.sha1(json.dumps(result.scene.to_dict() if result.scene else None, sort_keys=True,
                                    default=str).encode()).hexdigest()[:12]
    judged = [o for o in result.rollout.outcomes if o.verdict is not None]
    return max((d for *_, d in result.fused), default=0.0), [
        (scene, obs, o.oracle_success, f"seed {episode} subtask {o.index + 1}", str(o.oracle))
        for o, obs in zip(judged, recorder.seen, strict=True)]


def _run(job: tuple[str, int, str, str | None]) -> list[Row]:
    goal, episode, mesh_detail, cache = job
    path = Path(cache) / f"{goal}-{episode}-{mesh_detail}.pkl.gz" if cache else None
    depth, judged = cached(path, lambda: _rollout(goal, episode, mesh_detail))
    critic = make_critic(CriticConfig("image"))
    start = f" (starts interpenetrating: {1000 * depth:.1f} mm)" if depth > FUSED else ""
    rows: list[Row] = []
    for scene, obs, success, where, oracle in judged:
        verdict = critic.judge(obs)
        why = f"{where}{start}: {verdict.reason}; oracle {oracle}"
        rows.append((goal, scene, verdict.accept, success, why, depth > FUSED))
    return rows


def _pct(num: int, den: int, width: int = 7) -> str:
    return f"{num / den:{width}.1%}" if den else f"{'n/a':>{width}s}"


def _line(name: str, pairs: list[Row]) -> str:
    tp = sum(c and o for _, _, c, o, *_ in pairs)
    fp = sum(c and not o for _, _, c, o, *_ in pairs)
    fn = sum(not c and o for _, _, c, o, *_ in pairs)
    tn = sum(not c and not o for _, _, c, o, *_ in pairs)
    n, scenes = len(pairs), len({(g, s) for g, s, *_ in pairs})
    bal = f"{(tp / (tp + fn) + tn / (tn + fp)) / 2:8.1%}" if tp + fn and tn + fp else f"{'n/a':>8s}"
    return (f"{name:24s} {n:6d} {tp + fn:5d} {tn + fp:5d} {scenes:6d} {_pct(tp + tn, n)} {_pct(tp, tp + fp)} "
            f"{_pct(tp, tp + fn)} {_pct(tn, tn + fp, 9)} {bal}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=10, help="Vanilla rollouts per goal (episodes K..K+N-1)")
    parser.add_argument("--first-seed", type=int, default=0, help="K: the first episode (a later K gives "
                        "rollouts no check was tuned on)")
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--mesh-detail", choices=MESH_DETAILS, default=RenderConfig().mesh_detail,
                        help="how the critic's views draw the robot's meshes")
    parser.add_argument("--show-errors", action="store_true", help="print each disagreement")
    parser.add_argument("--cache", default=None, help="directory for the judged subtasks' observations")
    args = parser.parse_args()
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    cache = open_cache(args.cache, f"{fingerprint()} {ENTRIES}")
    jobs = [(g, s, args.mesh_detail, str(cache) if cache else None) for g in args.goals for s in seeds]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        pairs = [p for rows in pool.map(_run, jobs) for p in rows]
    print(f"image critic vs oracle on Vanilla rollouts (naive placement, no scene check), "
          f"{args.seeds} seeds per goal (from {args.first_seed}), every subtask judged, "
          f"mesh detail {args.mesh_detail}; "
          f"{time.perf_counter() - t0:.0f} s wall\n")
    print(f"{'goal':24s} {'judged':>6s} {'succ':>5s} {'fail':>5s} {'scenes':>6s} {'agree':>7s} {'prec':>7s} "
          f"{'recall':>7s} {'caught':>9s} {'bal.acc':>8s}")
    for goal in args.goals:
        print(_line(goal, [p for p in pairs if p[0] == goal]))
    print(_line("overall", pairs))
    print(f"\nby how the rollout starts (one of the plan's objects interpenetrating another deeper than "
          f"{1000 * FUSED:.0f} mm once the scene settled):")
    print(_line("clear at the start", [p for p in pairs if not p[5]]))
    print(_line("interpenetrating", [p for p in pairs if p[5]]))
    print("\nsucc/fail: judged subtasks the oracle says succeeded / failed; scenes: distinct scenes they "
          "come from; prec/recall: of the critic's accepts; caught: share of the oracle's failures the "
          "critic rejected; bal.acc: mean of recall and caught; n/a: empty denominator")
    if args.show_errors:
        for goal, _, accept, success, why, _ in pairs:
            if accept != success:
                print(f"  {'false accept' if accept else 'false reject'} {goal} {why}")


if __name__ == "__main__":
    main()
