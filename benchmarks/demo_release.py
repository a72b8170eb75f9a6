"""Where the hand let go: what a dataset's demonstrations teach in each pick-and-place subtask.

Label noise counts the demonstrations whose outcome is wrong; it does not say whether their
*actions* are wrong. A policy learns actions. For every pick-and-place subtask of every episode this
reads, from the dataset alone, the frame where the gripper command opens after its grasp (the
release) and measures, in the table's plane, how far the hand (``observation.ee_pose``) was from the
target object's centre (``observation.environment_state``) at that frame, and how far the carried
object was. Printed per dataset and carried object, split by the oracle's verdict on the subtask
(the episode's audit), with the sample each figure rests on:

    .venv/bin/python benchmarks/demo_release.py DATASET [DATASET ...]

A failed subtask whose hand let go over the target but whose object was elsewhere failed in what
the object did (a grasp that slipped or missed in clutter), not in where the hand went: its actions
are the expert's, aimed at the target. Subtasks with no release in their frames (a grasp that never
closed) are counted apart.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from pathlib import Path

import numpy as np

NEAR = 0.03  # metres: a release this close to the target's centre counts as over it
OPENS = 0.005  # how far the gripper command must open past its grasp to count as a release


def release_frame(gripper: np.ndarray) -> int | None:
    """The first frame after the gripper command's narrowest (the grasp) where it opens by
    :data:`OPENS`; None if it never closes and opens again."""
    low = int(np.argmin(gripper))
    opened = np.nonzero((np.arange(len(gripper)) > low) & (gripper > gripper[low] + OPENS))[0]
    return int(opened[0]) if len(opened) else None


def releases(root: Path) -> tuple[dict[tuple[bool, str], list[tuple[float, float]]], dict[bool, int]]:
    """Per (oracle success, carried object): (hand to target, object to target) at each release, in
    metres; and per oracle verdict, the subtasks without a release."""
    from vcage.data.reader import DatasetReader

    reader = DatasetReader(root, videos=False)
    names = reader.features["observation.environment_state"].names
    grip = reader.features["action.ee_pose"].names.index("gripper")
    found: dict[tuple[bool, str], list[tuple[float, float]]] = defaultdict(list)
    missing = {True: 0, False: 0}
    for index in range(len(reader)):
        episode = reader.episode(index)
        hand = episode.frames["observation.ee_pose"][:, :2]
        env = episode.frames["observation.environment_state"]
        subtasks = episode.extras["plan"]["subtasks"]
        for audit in episode.extras["oracle_audit"]:
            if audit["skill"] != "pick_and_place":
                continue
            args = subtasks[audit["subtask"]]["args"]
            if not isinstance(args.get("target"), str):
                continue  # put down at a position: no target object to measure against
            start, end = audit["frames"]
            ok = bool(audit["oracle_success"])
            at = release_frame(episode.frames["action.ee_pose"][start:end, grip])
            if at is None:
                missing[ok] += 1
                continue
            frame = start + at
            t, o = names.index(f"{args['target']}.x"), names.index(f"{args['obj']}.x")
            target = env[frame, t:t + 2]
            found[ok, args["obj"]].append((float(np.linalg.norm(hand[frame] - target)),
                                           float(np.linalg.norm(env[frame, o:o + 2] - target))))
    return found, missing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("datasets", nargs="+", type=Path)
    args = parser.parse_args()
    for root in args.datasets:
        found, missing = releases(root)
        print(f"{root}: pick-and-place subtasks by the oracle's verdict; at the release, the hand's and the "
              f"carried object's distance to the target's centre in the table's plane")
        print(f"  {'verdict':8s} {'object':8s} {'n':>4s}  {'hand: median':>12s} {'p90':>6s} "
              f"{'within ' + str(int(100 * NEAR)) + ' cm':>12s}  {'object: median':>14s} {'p90':>6s} "
              f"{'within ' + str(int(100 * NEAR)) + ' cm':>12s}")
        for ok in (True, False):
            for obj in sorted({o for k, o in found if k is ok}):
                d = np.array(found[ok, obj])
                hand, carried = d[:, 0], d[:, 1]
                print(f"  {'success' if ok else 'failure':8s} {obj:8s} {len(d):4d}  "
                      f"{100 * np.median(hand):9.1f} cm {100 * np.percentile(hand, 90):6.1f} "
                      f"{int((hand < NEAR).sum()):5d} ({np.mean(hand < NEAR):4.0%})  "
                      f"{100 * np.median(carried):11.1f} cm {100 * np.percentile(carried, 90):6.1f} "
                      f"{int((carried < NEAR).sum()):5d} ({np.mean(carried < NEAR):4.0%})")
        print(f"  no release in the subtask's frames: {missing[True]} successes, {missing[False]} failures")


if __name__ == "__main__":
    main()
