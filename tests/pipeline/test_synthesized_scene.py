"""Generation from a synthesized scene (issue 13, item 6): `vcage generate --scene DIR/scene.json`
starts the episodes from the synthesized poses and the dataset records the scene and its provenance."""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.config import Randomization
from vcage.data import DatasetReader
from vcage.data.layout import VCAGE_PATH
from vcage.errors import ConfigError
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.plan_layout import WORK_AREA, plan_layout
from vcage.planning import OfflinePlanner
from vcage.synthesis.scene_file import PlacedObject, ground_plan, load_scene

RUN = CliRunner()
INSTRUCTION = "put the mouse on the pad"
PROMPT = "a mouse to the left of a mouse pad"


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("syn")
    result = RUN.invoke(app, ["synthesize", PROMPT, "--out", str(out)])  # within the arm's reach
    assert result.exit_code == 0, result.output
    return out


def test_the_synthesized_scene_file_and_grounding(scene_dir: Path) -> None:
    scene = load_scene(scene_dir)
    assert scene.sha256 == hashlib.sha256((scene_dir / "scene.json").read_bytes()).hexdigest()
    assert scene.prompt == PROMPT and {o.type for o in scene.objects} == {"mouse_pad", "mouse"}
    cup = PlacedObject("cup", "cup", 0.5, 0.2, 0.0, color="blue")
    plate = PlacedObject("mouse_pad", "plate", 0.6, 0.25, 0.0)  # the plan's pad's name: renamed
    own = tuple(replace(o, name="pad_a") if o.type == "mouse_pad" else o for o in scene.objects)
    scene = replace(scene, objects=(*own, cup, plate))
    plan = OfflinePlanner().plan(INSTRUCTION)
    grounded, renamed = ground_plan(plan, scene)
    names = {o.name: o.type for o in grounded.objects}
    assert names == {o.name: o.type for o in renamed.objects}
    assert {o.name: o.type for o in plan.objects}.items() <= names.items()
    assert names["cup"] == "cup" and names["mouse_pad_2"] == "plate" and len(names) == 4
    assert grounded.object("cup").color == "blue" and grounded.subtasks == plan.subtasks
    layout = plan_layout(grounded, np.random.default_rng(0), Randomization(enabled=False), scene=renamed)
    for obj in layout.objects:
        placed = renamed.object(obj.name)
        assert placed is not None and obj.region is not None and obj.region.center == (placed.x, placed.y)
        assert obj.yaw == (placed.yaw, placed.yaw)
    plain = plan_layout(grounded, np.random.default_rng(0), Randomization(enabled=False))
    assert all(o.region == WORK_AREA and o.yaw == (-math.pi, math.pi) for o in plain.objects)
    with pytest.raises(ConfigError, match="needs a .*bell.* which the synthesized scene lacks"):
        ground_plan(OfflinePlanner().plan("press the bell"), scene)


def test_config_records_the_scene_only_when_given(scene_dir: Path) -> None:
    assert "synthesized" not in GenerateConfig().to_dict()  # runs without one write the same bytes
    cfg = GenerateConfig(synthesized=load_scene(scene_dir))
    again = GenerateConfig.from_dict(json.loads(json.dumps(cfg.to_dict())))
    assert again == cfg and again.data_dict()["synthesized"]["sha256"] == cfg.synthesized.sha256  # type: ignore[union-attr]


def test_generate_from_a_synthesized_scene(scene_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", INSTRUCTION, "--episodes", "1", "--out", str(out), "--scene",
                              str(scene_dir / "scene.json"), "--clutter", "0", "--size", "64"])
    assert result.exit_code == 0, result.output
    meta = json.loads((out / VCAGE_PATH).read_text())
    recorded = meta["config"]["generate"]["synthesized"]
    assert recorded["sha256"] == load_scene(scene_dir).sha256
    assert recorded["prompt"] == PROMPT
    assert recorded["source"] == str((scene_dir / "scene.json").resolve())
    assert {o["type"] for o in meta["config"]["plan"]["objects"]} == {"mouse_pad", "mouse"}
    episode = DatasetReader(out).episode(0)
    start = {o["name"]: o for o in episode.extras["scene"]["objects"]}
    rand = Randomization()
    for placed in recorded["objects"]:
        if placed["on"] is None:
            o = start[placed["name"]]
            assert abs(o["xy"][0] - placed["x"]) <= rand.object_xy.high + 1e-6
            assert abs(o["xy"][1] - placed["y"]) <= rand.object_xy.high + 1e-6


def test_a_job_grounds_the_plan_on_the_scene_its_configuration_holds(scene_dir: Path, tmp_path: Path) -> None:
    """Found on 2026-12-08: the CLI grounded the plan on a synthesized scene, the pipeline did not, so
    ``generate()`` given a configuration with a scene and no plan wrote an ungrounded plan."""
    from vcage.pipeline.generate import generate
    from vcage.pipeline.job import SceneSource, build_job

    scene = load_scene(scene_dir)
    grounded, _ = ground_plan(OfflinePlanner().plan(INSTRUCTION), scene)
    given = build_job(GenerateConfig(), INSTRUCTION, SceneSource(scene_file=scene_dir / "scene.json"))
    held = build_job(GenerateConfig(synthesized=scene), INSTRUCTION)  # e.g. a dataset's stored configuration
    assert given.plan == held.plan == grounded and given.cfg.synthesized == held.cfg.synthesized
    cfg = replace(GenerateConfig(synthesized=scene, seed=0),
                  render=replace(GenerateConfig().render, size=(64, 64)))
    generate(INSTRUCTION, 1, tmp_path / "api", cfg)
    stored = DatasetReader(tmp_path / "api").config or {}
    assert stored["plan"] == grounded.model_dump(mode="json")
    assert (GenerateConfig().scene_source, held.cfg.scene_source) == ("layout", "scene")
    with pytest.raises(ConfigError, match="one scene source; drop 'synthesis' or 'synthesized'"):
        GenerateConfig.from_dict({"synthesized": scene.to_dict(), "synthesis": {"prompt": PROMPT}})
    for source, message in ((SceneSource(synthesize=PROMPT, scene_file=scene_dir), "give no --scene"),
                            (SceneSource(subtasks=tmp_path / "db.sqlite"), "give no INSTRUCTION"),
                            (SceneSource(), None)):
        with pytest.raises(ConfigError, match=message or "give an INSTRUCTION"):
            build_job(GenerateConfig(), INSTRUCTION if message else None, source)


def test_bad_scenes_are_typed_errors(scene_dir: Path, tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "something else"}')
    for path, message in ((bad, "not a synthesized scene"), (tmp_path / "missing.json", "cannot read"),
                          (scene_dir, "which the synthesized scene lacks")):
        instruction = "press the bell" if path == scene_dir else INSTRUCTION
        result = RUN.invoke(app, ["generate", instruction, "--episodes", "1", "--out", str(tmp_path / "x"),
                                  "--scene", str(path)])
        assert result.exit_code == 2 and message in result.output, result.output
        assert not (tmp_path / "x").exists()  # nothing written before the refusal


def test_a_scene_where_the_goal_already_holds_is_refused_before_any_attempt(tmp_path: Path) -> None:
    """Found on 2026-12-05: a goal already true in the synthesized scene spent 20 attempts on "no
    free space"; now a typed refusal (exit 2) names the subtask and what to change, nothing written."""
    scene = tmp_path / "scene"
    assert RUN.invoke(app, ["synthesize", "an apple in a bowl", "--out", str(scene)]).exit_code == 0
    for source in (["--synthesize", "an apple in a bowl"], ["--scene", str(scene)]):
        result = RUN.invoke(app, ["generate", "put the apple in the bowl", "--episodes", "1",
                                  "--out", str(tmp_path / "x"), *source])
        assert result.exit_code == 2, result.output
        assert "asks for inside(apple, bowl), which already holds in the scene" in result.output
        assert "beside bowl" in result.output and not (tmp_path / "x").exists()
    plan = OfflinePlanner().plan("put the apple in the bowl")
    moved = load_scene(scene)  # the same scene with the apple beside the bowl: accepted
    moved = replace(moved, objects=tuple(replace(o, on=None, x=o.x + 0.15) if o.type == "apple" else o
                                         for o in moved.objects))
    grounded, _ = ground_plan(plan, moved)
    assert grounded.object("apple").on is None


@pytest.mark.slow
def test_every_attempt_can_start_from_a_scene_synthesized_for_it(tmp_path: Path) -> None:
    from vcage.pipeline.episode import attempt
    from vcage.pipeline.generate import generate
    from vcage.pipeline.plan_layout import episode_scene
    from vcage.planning.schema import Plan, PlanObject
    from vcage.synthesis.scene_file import SynthesisRequest

    out = tmp_path / "cli"
    made = RUN.invoke(app, ["generate", INSTRUCTION, "--synthesize", PROMPT, "--episodes", "1",
                            "--out", str(out), "--size", "64", "--cameras", "front", "--clutter", "1"])
    assert made.exit_code == 0, made.output
    stored = DatasetReader(out).config or {}
    cfg = GenerateConfig.from_dict(stored["generate"])
    assert cfg.synthesis == SynthesisRequest(PROMPT) and cfg.synthesized is None
    plan = Plan.model_validate(stored["plan"])
    assert {o.type for o in plan.objects} == {"mouse", "mouse_pad"}
    # without randomisation each episode's objects stand exactly where its own scene put them
    cfg = replace(cfg, randomization=Randomization(enabled=False))
    root = tmp_path / "api"
    generate(INSTRUCTION, 2, root, cfg, plan=plan)
    reader = DatasetReader(root)
    starts = []
    for i in range(2):
        extras = reader.extras(i)
        own = episode_scene(plan, cfg.synthesis, extras["seed"])
        placed = {o["name"]: tuple(o["xy"]) for o in extras["scene"]["objects"]}
        assert all(placed[o.name] == pytest.approx((o.x, o.y)) for o in own.objects)
        starts.append(placed)
    assert starts[0] != starts[1]  # a new scene per episode, not one scene jittered
    # the evaluation environment of such a dataset synthesizes its scenes the same way
    from vcage.pipeline.evaluation import make_env

    env = make_env(reader.config or {}, seed=3)
    env.reset()
    assert env.world is not None and env.scene_seed is not None
    own = episode_scene(plan, cfg.synthesis, env.scene_seed)
    for o in own.objects:
        assert env.world.object_pos(o.name)[:2] == pytest.approx((o.x, o.y), abs=0.01)
    env.close()
    # a plan the synthesized scene cannot hold: the attempt is refused, naming synthesis
    extra = plan.model_copy(update={"objects": (*plan.objects, PlanObject(name="cup", type="cup"))})
    refused = attempt(extra, 7, cfg, None)
    assert refused.stage == "placement" and refused.reason.startswith("synthesis: ")
    assert "cup" in refused.reason
