"""End-to-end generation into a real dataset: verification, audit log, determinism, appends."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest

from vcage.config import RenderConfig
from vcage.critics.image import ImageCritic
from vcage.data import DatasetReader
from vcage.data.layout import ATTEMPTS_LOG, RUNS_LOG, VCAGE_PATH
from vcage.errors import ConfigError, DatasetError, PlanningError, RegistryError, SceneError
from vcage.pipeline.attempt_log import read
from vcage.pipeline.audit import audit
from vcage.pipeline.config import ExecutorConfig, GenerateConfig
from vcage.pipeline.generate import generate
from vcage.provenance import software
from vcage.scene.compose import compose
from vcage.scene.instantiate import SceneConfig
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig
from vcage.tasks import predicates as P

SHORT = "press the bell"
SMALL = {"scene": SceneConfig(clutter=2), "render": RenderConfig(size=(64, 64))}


def test_generate_writes_a_verified_dataset(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    funnel = generate("put the mouse on the pad, then press the bell", 1, out, GenerateConfig(**SMALL))
    assert funnel.accepted == 1 and funnel.label_noise == 0.0
    reader = DatasetReader(out)
    assert reader.num_episodes == 1 and set(reader.cameras) == {"observation.images.front",
                                                                 "observation.images.wrist"}
    ep = reader.episode(0)
    extras = ep.extras
    assert extras["oracle_success"] and extras["plan"]["subtasks"][1]["skill"] == "press"
    assert [s["verdict"]["accept"] for s in extras["subtasks"]] == [True, True]
    # which rules judged: the critic's version on every verdict, its thresholds in the run's log line
    version = ImageCritic().version()
    assert version.startswith("image@")
    assert [s["verdict"]["critic"] for s in extras["subtasks"]] == [version] * 2
    bounds = [s["frames"] for s in extras["subtasks"]]
    assert bounds[0][0] == 0 and bounds[0][1] <= bounds[1][0] and bounds[1][1] <= ep.length
    assert ep.arrays["states"].shape[0] == ep.length
    assert reader.video(0, "observation.images.front").shape == (ep.length, 64, 64, 3)
    stats = read(out / RUNS_LOG)[-1]
    assert stats["accepted"] == 1 and stats["stages"]["accepted"] == 1
    seconds = stats["seconds"]
    assert seconds["physics"] > 0 and seconds["render"] > 0
    assert seconds["physics"] + seconds["render"] <= stats["wall_seconds"]
    # the versions the episodes depend on (the same seed gives the same episode only under them)
    assert stats["software"]["mujoco"] == mujoco.__version__ and stats["software"]["mink"] != "absent"
    # and the code: the commit, the package's digest and the lock file's hash, in the run and the episode
    assert stats["software"] == extras["software"] == software()
    assert {"commit", "source", "lock"} <= set(extras["software"])
    assert stats["critic"] == {"version": version, "rules": ImageCritic().rules()}
    assert stats["critic"]["rules"]["NEAR"] == 0.1 and len(stats["critic"]["rules"]) > 40
    report = audit(out)
    assert report.accepted == 1 and report.agreement == 1.0 and report.judged_subtasks == 2


def test_same_seed_same_episode_and_replayable_states(tmp_path: Path) -> None:
    a = tmp_path / "a"
    b = tmp_path / "b"
    generate(SHORT, 1, a, GenerateConfig(**SMALL, seed=3))
    generate(SHORT, 1, b, GenerateConfig(**SMALL, seed=3))
    ea, eb = DatasetReader(a).episode(0), DatasetReader(b).episode(0)
    np.testing.assert_array_equal(ea.frames["action"], eb.frames["action"])
    assert ea.extras["seed"] == eb.extras["seed"] and ea.extras["scene"] == eb.extras["scene"]
    # the dataset alone rebuilds the world and replays it: the oracle holds in the last state
    scene = SceneSpec.from_dict(ea.extras["scene"])
    assert json.loads(json.dumps(scene.to_dict())) == ea.extras["scene"]
    world = compose(scene).make_world()

    def pressed_at(frame: int) -> bool:
        world.set_state(ea.arrays["states"][frame])
        world.forward()
        return P.pressed(world, "bell")

    start, end = ea.extras["subtasks"][0]["frames"]
    assert not pressed_at(start) and any(pressed_at(f) for f in range(start, end))
    assert not pressed_at(end - 1) and P.upright(world, "bell")  # released again, still standing
    with pytest.raises(SceneError, match="not a scene spec"):
        SceneSpec.from_dict({"objects": [{"name": "x"}]})


@pytest.mark.slow
def test_workers_make_the_same_dataset(tmp_path: Path) -> None:
    cfg = GenerateConfig(**SMALL)
    one = generate(SHORT, 2, tmp_path / "one", cfg)
    two = generate(SHORT, 2, tmp_path / "two", replace(cfg, executor=ExecutorConfig(workers=2)))
    assert (one.accepted, one.attempts) == (two.accepted, two.attempts) and two.workers == 2
    a, b = DatasetReader(tmp_path / "one"), DatasetReader(tmp_path / "two")
    for k in range(2):
        assert a.extras(k)["seed"] == b.extras(k)["seed"]
        np.testing.assert_array_equal(a.episode(k).arrays["states"], b.episode(k).arrays["states"])
        np.testing.assert_array_equal(a.video(k, "observation.images.front"),
                                      b.video(k, "observation.images.front"))
    logs = [(tmp_path / d / ATTEMPTS_LOG).read_text().splitlines() for d in ("one", "two")]
    assert [json.loads(r)["seed"] for r in logs[0]] == [json.loads(r)["seed"] for r in logs[1]]
    stats = read(tmp_path / "two" / RUNS_LOG)[-1]
    assert stats["core_seconds"] == pytest.approx(2 * stats["wall_seconds"], rel=0.01)
    # the workers are stored with each episode, yet do not change what must match to append
    assert b.extras(0)["config"]["executor"]["workers"] == 2
    assert json.loads((tmp_path / "one" / VCAGE_PATH).read_text()) == \
        json.loads((tmp_path / "two" / VCAGE_PATH).read_text())
    generate(SHORT, 1, tmp_path / "one", replace(cfg, executor=ExecutorConfig(workers=2)))
    with pytest.raises(ConfigError, match="executor ray"):
        generate(SHORT, 1, tmp_path / "bad", replace(cfg, executor=ExecutorConfig(address="auto")))
    with pytest.raises(RegistryError, match="valid names: local, ray"):
        generate(SHORT, 1, tmp_path / "bad", replace(cfg, executor=ExecutorConfig("slurm")))
    assert not (tmp_path / "bad" / "meta").exists()


@pytest.mark.slow
def test_ray_executor_makes_the_same_dataset(tmp_path: Path) -> None:
    ray = pytest.importorskip("ray")
    cfg = GenerateConfig(**SMALL)
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False,
             object_store_memory=128 * 1024 * 1024)
    try:
        remote = generate(SHORT, 2, tmp_path / "ray",
                          replace(cfg, executor=ExecutorConfig("ray", workers=2)))
    finally:
        ray.shutdown()
    local = generate(SHORT, 2, tmp_path / "local", cfg)
    assert (remote.accepted, remote.attempts) == (local.accepted, local.attempts) == (2, 2)
    a, b = DatasetReader(tmp_path / "local"), DatasetReader(tmp_path / "ray")
    for k in range(2):
        np.testing.assert_array_equal(a.episode(k).arrays["states"], b.episode(k).arrays["states"])


def test_append_needs_the_same_config_and_keeps_episodes(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    generate(SHORT, 1, out, GenerateConfig(**SMALL))
    generate(SHORT, 1, out, GenerateConfig(**SMALL))
    assert DatasetReader(out).num_episodes == 2
    with pytest.raises(DatasetError, match="different configuration"):
        generate(SHORT, 1, out, replace(GenerateConfig(**SMALL), scene=SceneConfig(clutter=5)))
    assert DatasetReader(out).num_episodes == 2
    assert len((out / ATTEMPTS_LOG).read_text().splitlines()) == 2


def test_vanilla_accepts_without_a_critic(tmp_path: Path) -> None:
    out = tmp_path / "vanilla"
    funnel = generate(SHORT, 1, out, GenerateConfig.vanilla(clutter=2, render=RenderConfig(size=(64, 64))))
    assert funnel.accepted == 1
    extras = DatasetReader(out).extras(0)
    assert extras["config"]["critic"] is None and extras["subtasks"][0]["verdict"] is None
    assert extras["config"]["scene"]["placement"] == "naive" and not extras["config"]["scene"]["check"]
    assert audit(out).judged_subtasks == 0


def _vanilla_fused(tmp_path: Path, tries: int = 30) -> tuple[int, Path, dict]:
    """The first run seed whose Vanilla episode of :data:`SHORT` (eight distractors) starts with the
    bell fused into another object, its dataset and its attempt record: found by the property, not
    named, so that a release of the simulator that moves which seed does so moves no test."""
    for seed in range(tries):
        out = tmp_path / f"vanilla-{seed}"
        cfg = GenerateConfig.vanilla(seed=seed, clutter=8, render=RenderConfig(size=(64, 64)))
        generate(SHORT, 1, out, cfg)
        record = json.loads((out / ATTEMPTS_LOG).read_text().splitlines()[-1])
        if record["fused_at_start"]:
            return seed, out, record
        shutil.rmtree(out)
    raise AssertionError(f"no Vanilla episode of {tries} seeds started fused: naive placement no longer "
                         "fuses objects as often as it did (about one scene in three)")


@pytest.mark.slow
def test_a_vanilla_episode_that_starts_fused_says_so_in_its_log_and_audit(tmp_path: Path) -> None:
    """Naive placement can put the bell into a distractor, and settling leaves them so: the attempt
    log names the pair and its depth, and the audit counts the accepted episode among those that
    started fused. A checked scene never starts so."""
    seed, out, record = _vanilla_fused(tmp_path)
    for a, b, depth in record["fused_at_start"]:
        assert "bell" in (a, b) and a != b and depth > StabilityConfig().penetration
    report = audit(out)
    noise = 0.0 if record["oracle_success"] else 1.0
    assert (report.accepted, report.accepted_fused) == (1, 1)
    assert report.noise_where(True) == noise and report.noise_where(False) is None
    assert "1 of them started with the plan's objects fused" in report.summary()
    checked = tmp_path / "checked"
    generate(SHORT, 1, checked, GenerateConfig(seed=seed, **SMALL))
    assert json.loads((checked / ATTEMPTS_LOG).read_text().splitlines()[-1])["fused_at_start"] == []
    assert audit(checked).accepted_fused == 0 and "fused" not in audit(checked).summary()


def test_ungroundable_instruction_writes_nothing(tmp_path: Path) -> None:
    out = tmp_path / "none"
    with pytest.raises(PlanningError):
        generate("fly to the moon", 1, out, GenerateConfig(**SMALL))
    assert not out.exists()
