"""Recovery data: pushed execution, clean labels, seeded, refused when out of range, stored with the data."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from vcage.errors import ConfigError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.generate import generate
from vcage.sim.robot import HOME_QPOS
from vcage.sim.world import World
from vcage.skills.motion import MotionPlan, Waypoint
from vcage.skills.playback import Player
from vcage.skills.recovery import Perturbation, RecoveryConfig

PUSHED = RecoveryConfig(fraction=1.0, joint_noise=0.08)


def plan() -> MotionPlan:
    home = np.asarray(HOME_QPOS, dtype=float)
    out = home + np.array([0.4, 0.2, -0.3, -0.2, 0.1, 0.3, -0.4])
    return MotionPlan("test", (Waypoint(out, 1.0, 1.5, hold=0.2), Waypoint(home, 1.0, 1.5)))


def play(world: World, perturbation: Perturbation | None) -> dict[str, np.ndarray]:
    world.reset()
    player = Player(world, perturbation=perturbation)
    player.run(plan())
    player.wait(1.0)  # no push while waiting: the arm settles where the plan ends
    return player.recording.arrays()


def test_a_pushed_segment_keeps_the_plans_command_as_the_action_while_the_arm_leaves_the_path(
        world: World) -> None:
    clean = play(world, None)
    pushed = play(world, Perturbation(PUSHED, seed=7))
    np.testing.assert_array_equal(pushed["action"], clean["action"])  # the labels are the plan's
    gap = np.abs(pushed["qpos"] - clean["qpos"]).max(axis=0)
    assert gap.max() > 0.03  # the arm was really pushed off the demonstrated path
    # the push is a bump: zero again at the segments' ends, so the arm comes back to the plan
    np.testing.assert_allclose(pushed["qpos"][-1], clean["qpos"][-1], atol=0.005)


def test_the_pushes_are_seeded_and_a_segment_not_pushed_does_not_shift_the_next(world: World) -> None:
    a, b = play(world, Perturbation(PUSHED, 7)), play(world, Perturbation(PUSHED, 7))
    np.testing.assert_array_equal(a["qpos"], b["qpos"])
    assert not np.array_equal(a["qpos"], play(world, Perturbation(PUSHED, 8))["qpos"])
    half = Perturbation(RecoveryConfig(fraction=0.5, joint_noise=0.08), 3)
    full = Perturbation(PUSHED, 3)
    for _ in range(20):  # the same draws: where both push, they push alike
        x, y = half.offsets(10, 7), full.offsets(10, 7)
        assert y is not None and (x is None or np.array_equal(x, y))
    assert 0 < half.pushed < 20 and full.pushed == 20


def test_nothing_is_pushed_at_fraction_zero_and_the_start_moves_only_with_start_noise(world: World) -> None:
    off = Perturbation(RecoveryConfig(fraction=0.0, joint_noise=0.08), 1)
    np.testing.assert_array_equal(play(world, off)["qpos"], play(world, None)["qpos"])
    assert not np.any(off.start_offset(7))
    assert np.abs(Perturbation(RecoveryConfig(start_noise=0.05), 1).start_offset(7)).max() > 0


@pytest.mark.parametrize("fields, message", [
    ({"fraction": 1.5}, "share of motion segments"),
    ({"fraction": -0.1}, "share of motion segments"),
    ({"joint_noise": 0.5}, "joint_noise must be in"),
    ({"start_noise": -0.01}, "start_noise must be in"),
    ({"joint_noise": float("nan")}, "must be a number"),
    ({"fraction": True}, "must be a number"),
])
def test_out_of_range_recovery_settings_are_refused(fields: dict[str, object], message: str) -> None:
    with pytest.raises(ConfigError, match=message):
        RecoveryConfig(**fields)  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match=message):
        GenerateConfig.from_dict({"recovery": fields})


def test_a_recovery_dataset_stores_its_settings_and_the_same_seed_gives_the_same_episode(
        tmp_path: Path) -> None:
    cfg = replace(GenerateConfig(seed=3),
                  recovery=RecoveryConfig(fraction=0.5, joint_noise=0.05, start_noise=0.05))
    for name in ("a", "b"):
        generate("press the bell", 1, tmp_path / name, cfg)
    stored = json.loads((tmp_path / "a" / "meta" / "vcage.json").read_text())["config"]["generate"]
    assert stored["recovery"] == {"fraction": 0.5, "joint_noise": 0.05, "start_noise": 0.05}
    assert GenerateConfig.from_dict(stored).recovery == cfg.recovery
    data = sorted((tmp_path / "a" / "data").rglob("*.parquet"))
    assert data and all(p.read_bytes() == (tmp_path / "b" / p.relative_to(tmp_path / "a")).read_bytes()
                        for p in data)
    assert "recovery" not in GenerateConfig(seed=3).to_dict()  # off: stored as before it existed
