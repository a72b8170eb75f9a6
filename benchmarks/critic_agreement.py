"""The image critic against the oracle on hard cases: Vanilla rollouts, judged but never stopped.

In a V-CAGE run few subtasks fail (the scenes are valid), so the critic's agreement there rests on
few negatives. Here every goal runs with naive placement and no scene check (the Vanilla setting,
where most episodes fail), the image critic judges every subtask from the rendered views, and the
rollout continues whatever it says, so each subtask gives one (critic, oracle) pair. Subtasks whose
skill could not plan are left out (no critic is asked about them in a run either). Episode k
uses the seed of the first attempt at episode k in ``vcage_vs_vanilla``'s Vanilla run.

Printed per goal and overall: judged subtasks, the oracle's failures among them, agreement,
precision and recall of "accept" (as in ``vcage audit``), and the share of the oracle's failures the
critic rejected (what keeps them out of a dataset).

    LP_NUM_THREADS=1 .venv/bin/python benchmarks/critic_agreement.py --seeds 10 --workers 2

``--mesh-detail full`` renders the critic's views with the robot's meshes as shipped (the default
is the simplified meshes, as in a run).
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor

os.environ.setdefault("LP_NUM_THREADS", "1")  # one rasteriser thread: a worker is one core

from vcage.config import MESH_DETAILS, RenderConfig  # noqa: E402
from vcage.critics import Critic, CriticConfig, Observation, Verdict, make_critic  # noqa: E402
from vcage.pipeline.config import GenerateConfig  # noqa: E402
from vcage.pipeline.episode import attempt  # noqa: E402
from vcage.planning import make_planner  # noqa: E402
from vcage.planning.goals import GOALS  # noqa: E402

DEFAULT_GOALS = ("get_ready_for_work", "prepare_breakfast", "tidy_the_desk", "set_the_table",
                 "build_a_tower", "sort_blocks_by_colour")


class Shadow(Critic):
    """Asks ``inner`` and keeps its verdicts, but always lets the rollout go on."""

    def __init__(self, inner: Critic) -> None:
        self.inner, self.verdicts = inner, []  # type: list[Verdict]
        self.needs_views = inner.needs_views

    def judge(self, obs: Observation) -> Verdict:
        self.verdicts.append(self.inner.judge(obs))
        return Verdict(True, "shadow: the rollout continues")


def _run(job: tuple[str, int, str]) -> list[tuple[str, bool, bool]]:
    goal, episode, mesh_detail = job
    phrase = next(g for g in GOALS if g.name == goal).phrasings[0]
    plan = make_planner("offline").plan(phrase)
    # episode k: the seed of the Vanilla run's episode k
    cfg = GenerateConfig.vanilla(seed=0, render=RenderConfig(mesh_detail=mesh_detail))
    shadow = Shadow(make_critic(CriticConfig("image")))
    result = attempt(plan, cfg.episode_seed(episode, 0), cfg, shadow)
    if result.rollout is None:
        return []
    judged = [o for o in result.rollout.outcomes if o.verdict is not None]
    return [(goal, v.accept, o.oracle_success) for o, v in zip(judged, shadow.verdicts, strict=True)]


def _line(name: str, pairs: list[tuple[str, bool, bool]]) -> str:
    tp = sum(c and o for _, c, o in pairs)
    fp = sum(c and not o for _, c, o in pairs)
    fn = sum(not c and o for _, c, o in pairs)
    tn = sum(not c and not o for _, c, o in pairs)
    n = len(pairs)
    return (f"{name:24s} {n:6d} {tn + fp:8d} {(tp + tn) / max(1, n):7.1%} {tp / max(1, tp + fp):7.1%} "
            f"{tp / max(1, tp + fn):7.1%} {tn / max(1, tn + fp):9.1%}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", type=int, default=10, help="Vanilla rollouts per goal (episodes 0..N-1)")
    parser.add_argument("--goals", nargs="*", default=list(DEFAULT_GOALS))
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--mesh-detail", choices=MESH_DETAILS, default=RenderConfig().mesh_detail,
                        help="how the critic's views draw the robot's meshes")
    args = parser.parse_args()
    jobs = [(g, s, args.mesh_detail) for g in args.goals for s in range(args.seeds)]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        pairs = [p for rows in pool.map(_run, jobs) for p in rows]
    print(f"image critic vs oracle on Vanilla rollouts (naive placement, no scene check), "
          f"{args.seeds} seeds per goal, every subtask judged, mesh detail {args.mesh_detail}; "
          f"{time.perf_counter() - t0:.0f} s wall\n")
    print(f"{'goal':24s} {'judged':>6s} {'failures':>8s} {'agree':>7s} {'prec':>7s} {'recall':>7s} "
          f"{'caught':>9s}")
    for goal in args.goals:
        print(_line(goal, [p for p in pairs if p[0] == goal]))
    print(_line("overall", pairs))
    print("\nfailures: subtasks the oracle says failed; prec/recall: of the critic's accepts; caught: "
          "share of the oracle's failures the critic rejected")


if __name__ == "__main__":
    main()
