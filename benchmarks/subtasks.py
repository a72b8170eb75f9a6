"""The verification funnel over every candidate subtask of the atomic task scenes and synthesized scenes.

    .venv/bin/python benchmarks/subtasks.py --trials 10 --workers 2 --synthesize 10
    .venv/bin/python benchmarks/subtasks.py --trials 5 --tasks press_stapler place_mouse_pad --silent 0

Scenes: each atomic task's scene (seed 0, as its episodes are randomised) and, with
``--synthesize N``, N scenes made by ``vcage synthesize`` from N prompts (kept under ``--out``,
reused when there), plus any ``--scenes`` paths. Every candidate subtask of every scene is verified
with ``--trials`` trials and the ``--critic`` (offline image critic by default); the funnel
(candidates, valid, ran, succeeded, accepted), the SR distribution and the failure classes are
printed. *Correct template subtasks* are the task scenes' candidates that are the task's own subtask
(the object and target, or the pressed point, its scripted expert uses): the share accepted is the
figure the issue asks >= 99 % of. *Silent failures* (``--silent`` trials each, 0 to skip): for
every candidate one program that runs cleanly but does the wrong thing (puts the object 15 cm off
its target on the table; for a press, only retreats); none may be accepted.

With ``--codegen S`` it prints the code-generation table instead (the appendix's shape: Avg SR,
Top-3 SR, pass@k) for the tasks' own subtasks: the offline reference program (the template written
as a program), and five completions replayed by a local OpenAI-compatible server
(tests/backends/fake_openai.py): good, buggy (IndexError), near-miss (the silent failure above),
malicious and prose; expected per task: Avg SR = reference SR / 5, pass@1 = 1/5 when it is accepted.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import vcage  # noqa: F401  (sets the GL backend before MuJoCo renders)
from vcage.critics.base import CriticConfig, make_critic
from vcage.scene.spec import SceneSpec
from vcage.subtasks.candidates import Candidate, candidates
from vcage.subtasks.evaluate import TaskScore, sample_programs, score, table
from vcage.subtasks.records import SceneRecord, SubtaskRecord, TrialRecord
from vcage.subtasks.scenes import resolve
from vcage.subtasks.store import SubtaskStore
from vcage.subtasks.trial import TrialConfig
from vcage.subtasks.verify import Funnel, verify
from vcage.tasks import TASKS, make_task

PROMPTS = ["organize the breakfast table", "tidy the desk", "serve tea", "set the table", "display the fruit",
           "put the apple in the bowl and the cup left of the plate", "put the bread in the basket",
           "a mug next to a plate", "some fruit", "do the paperwork", "press the bell", "stack the blocks"]


def own_subtask(task: str) -> dict[str, str] | None:
    """The skill arguments of an atomic task's own subtask, when it is a template's (place or press)."""
    t = make_task(task)
    obj, target, point = getattr(t, "obj", None), getattr(t, "target", None), getattr(t, "point", None)
    if obj is None:
        return None
    if target is not None:
        return {"obj": obj, "target": target}
    return {"obj": obj, "point": point} if point else None


def silent(c: Candidate, spec: SceneSpec) -> Candidate:
    """A program that runs without an error and misses the subtask's goal."""
    if c.skill != "pick_and_place":
        return c.with_program("retreat()\n", "silent-failure", "0" * 64)
    t = spec.object(c.args["target"])
    x0, x1 = spec.table.x_range
    x = t.xy[0] - 0.15 if t.xy[0] - 0.15 > x0 + 0.1 else t.xy[0] + 0.15
    code = f"t = position({c.args['target']!r})\npick_and_place(obj={c.args['obj']!r}, xy=({x:.3f}, t[1]))\n"
    return c.with_program(code, "silent-failure", "0" * 64)


def _verify(job: tuple[Candidate, SceneSpec, int, str]) -> tuple[SubtaskRecord, list[TrialRecord], Funnel]:
    cand, spec, trials, critic = job
    judge = None if critic == "none" else make_critic(CriticConfig(critic))
    return verify(cand, spec, judge, TrialConfig(trials=trials), critic)


def synthesized(out: Path, n: int) -> list[str]:
    """``n`` synthesized scenes (prompt i with seed i, prompts reused with new seeds), skipping failures."""
    dirs: list[str] = []
    for i, prompt in enumerate(PROMPTS * 3):
        if len(dirs) == n:
            break
        d = out / f"syn-{i:02d}"
        if not (d / "scene_spec.json").exists():
            done = subprocess.run([sys.executable, "-m", "vcage.cli", "synthesize", prompt, "--out", str(d),
                                   "--seed", str(i)], capture_output=True, text=True)
            if done.returncode != 0:
                print(f"synthesis of {prompt!r} (seed {i}) failed: {' '.join(done.stdout.split())[-160:]}")
                continue
        dirs.append(str(d))
    return dirs


def _score(job: tuple[Candidate, SceneSpec, list[str], int, str]) -> TaskScore:
    cand, spec, programs, seeds, model = job
    return score(cand, spec, programs, seeds, None, TrialConfig(), model)


def replays(c: Candidate, spec: SceneSpec) -> list[str]:
    """A replayed model's five completions: good, buggy, near-miss, malicious, prose."""
    good = c.program_text()
    return [f"```python\n{good}```", f"```python\np = position({c.args['obj']!r})\nx = p[7]\n{good}```",
            f"```python\n{silent(c, spec).code}```", "```python\nimport os\nos.system('id')\n```",
            "First move the arm over the object, then carefully do the task."]


def codegen(scenes: list[tuple[str, SceneRecord, SceneSpec]], seeds: int, workers: int) -> None:
    """The appendix's table for the tasks' own subtasks: reference programs and replayed completions."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
    from backends.fake_openai import FakeOpenAI
    from vcage.backends import BackendConfig, connect

    tasks = []
    for ref, scene, spec in scenes:
        own = own_subtask(ref[5:]) if ref.startswith("task:") else None
        tasks += [(c, spec) for c in candidates(scene.id, spec) if c.args == own]
    jobs = [(c, spec, [c.program_text()], seeds, "reference") for c, spec in tasks]
    with FakeOpenAI("replay") as server:
        backend = connect(BackendConfig(base_url=server.base_url, model="replay", max_retries=0))
        for c, spec in tasks:
            server.script(*replays(c, spec))
            jobs.append((c, spec, sample_programs(backend, c, spec, 5), seeds, "replay"))
    with ProcessPoolExecutor(workers) as pool:
        scores = list(pool.map(_score, jobs))
    rows = [(job[4], s) for job, s in zip(jobs, scores, strict=True)]
    print(table(rows))
    for source in ("reference", "replay"):
        group = [s for src, s in rows if src == source]
        print(f"{source}: {len(group)} tasks, mean Avg SR {sum(s.avg_sr for s in group) / len(group):.3f}, "
              f"mean Top-3 SR {sum(s.top3_sr for s in group) / len(group):.3f}, "
              f"mean pass@1 {sum(s.pass_at(1) or 0 for s in group) / len(group):.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--silent", type=int, default=3, help="trials per silent-failure program (0: skip)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--critic", default="image")
    parser.add_argument("--tasks", nargs="*", default=None,
                        help="task scenes to include (default: every task; --tasks alone: none)")
    parser.add_argument("--synthesize", type=int, default=0, help="synthesized scenes to add")
    parser.add_argument("--scenes", nargs="*", default=[], help="more scene_spec.json files or directories")
    parser.add_argument("--out", type=Path, default=Path("out/bench_subtasks"))
    parser.add_argument("--rerun", type=int, default=0, help="re-verify this many candidates and compare")
    parser.add_argument("--codegen", type=int, default=0,
                        help="instead of the funnel: the code-generation table, this many seeds a program")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    refs = [f"task:{t}" for t in (TASKS.names() if args.tasks is None else args.tasks)]
    refs += synthesized(args.out, args.synthesize) + args.scenes
    scenes: list[tuple[str, SceneRecord, SceneSpec]] = []
    for ref in refs:
        scene, spec = resolve(ref)
        scenes.append((ref, scene, spec))
    if args.codegen:
        codegen(scenes, args.codegen, args.workers)
        return
    jobs, own_ids, silent_jobs = [], set(), []
    for ref, scene, spec in scenes:
        own = own_subtask(ref[5:]) if ref.startswith("task:") else None
        for c in candidates(scene.id, spec):
            jobs.append((c, spec, args.trials, args.critic))
            if own is not None and c.args == own:
                own_ids.add(c.id)
            if args.silent:
                silent_jobs.append((silent(c, spec), spec, args.silent, args.critic))
    n_task = sum(r.startswith("task:") for r in refs)
    print(f"{len(scenes)} scenes ({n_task} task scenes), {len(jobs)} candidates, "
          f"{args.trials} trials each, critic {args.critic}, {args.workers} workers")
    t0 = time.perf_counter()
    db = args.out / "subtasks.db"
    results = []
    with ProcessPoolExecutor(args.workers) as pool, SubtaskStore(db) as store:
        for _, scene, _ in scenes:
            store.add_scene(scene)
        for i, (record, trials, f) in enumerate(pool.map(_verify, jobs), 1):
            store.put(record, trials)  # stored as it comes: a cut-short run keeps what it verified
            results.append((record, trials, f))
            print(f"  [{i}/{len(jobs)} {(time.perf_counter() - t0) / 60:.1f} min] {record.id} "
                  f"{record.status:8} {record.description}: {record.reason}", flush=True)
        silent_results = list(pool.map(_verify, silent_jobs))
    minutes = (time.perf_counter() - t0) / 60
    funnel = Funnel()
    failures: Counter[str] = Counter()
    rates: Counter[str] = Counter()
    for record, trials, f in results:
        funnel.add(f)
        failures.update(t.failure_class for t in trials if not t.success)
        if record.trials:
            rates[f"{record.success_rate:.1f}"] += 1
    print("funnel: " + ", ".join(f"{k} {v}" for k, v in funnel.to_dict().items()))
    print("SR distribution (candidates per SR): " + ", ".join(f"{k}: {v}" for k, v in sorted(rates.items())))
    print("trial failures by class: " + (", ".join(f"{k} {v}" for k, v in failures.most_common()) or "none"))
    own = [r for r, _, _ in results if r.id in own_ids]
    ok = sum(r.status == "accepted" for r in own)
    print(f"correct template subtasks (the tasks' own) accepted: {ok}/{len(own)}"
          + (f" ({100 * ok / len(own):.1f} %)" if own else "")
          + "; rejected: " + ("; ".join(f"{r.description} [{r.reason}]" for r in own
                                        if r.status != "accepted") or "none"))
    task_ids = {s.id for ref, s, _ in scenes if ref.startswith("task:")}
    for label, group in (("task scenes", [r for r, _, _ in results if r.scene_id in task_ids]),
                         ("synthesized scenes", [r for r, _, _ in results if r.scene_id not in task_ids])):
        if group:
            print(f"{label}: {sum(r.status == 'accepted' for r in group)}/{len(group)} candidates accepted")
    if args.silent:
        accepted_silent = [r for r, _, _ in silent_results if r.status == "accepted"]
        print(f"silent-failure programs accepted: {len(accepted_silent)}/{len(silent_results)} "
              f"({args.silent} trials each)"
              + "".join(f"\n  {r.description}: {r.code!r}" for r in accepted_silent))
    if args.rerun:
        again = [_verify(job) for job in jobs[:args.rerun]]
        same = sum([(t.seed, t.outcome, t.failure_class, t.detail) for t in a[1]]
                   == [(t.seed, t.outcome, t.failure_class, t.detail) for t in b[1]]
                   for a, b in zip(results, again, strict=False))
        print(f"rerun: {same}/{len(again)} candidates gave identical trials (seed, outcome, class, detail) "
              f"over {args.trials} trials each")
    print(f"wall time {minutes:.1f} min; database {db}")


if __name__ == "__main__":
    main()
