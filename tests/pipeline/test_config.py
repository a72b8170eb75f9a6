"""The configuration tree: round trips, presets, validation before work, endpoints resolved once."""

from __future__ import annotations

import json
from dataclasses import replace

import pytest

from vcage.backends import BackendConfig
from vcage.config import CAMERAS, RenderConfig
from vcage.critics import CriticConfig
from vcage.errors import ConfigError, RegistryError
from vcage.pipeline.config import ExecutorConfig, GenerateConfig
from vcage.planning import PlannerConfig
from vcage.scene.instantiate import SceneConfig


@pytest.mark.parametrize("cfg", [
    GenerateConfig(),
    GenerateConfig.vanilla(seed=7, clutter=2),
    GenerateConfig(planner=PlannerConfig("llm", BackendConfig(base_url="http://localhost:9/v1", model="m")),
                   critic=CriticConfig("vlm", BackendConfig(base_url="http://localhost:9/v1", model="v"),
                                       votes=3, rule="all"),
                   render=RenderConfig(cameras=("top",), size=(64, 48)),
                   executor=ExecutorConfig("ray", workers=2, address="auto")),
])
def test_the_tree_round_trips_through_json(cfg: GenerateConfig) -> None:
    data = json.loads(json.dumps(cfg.to_dict()))
    assert GenerateConfig.from_dict(data) == cfg
    assert "executor" not in cfg.data_dict() and cfg.data_dict()["seed"] == cfg.seed


def test_vanilla_is_a_preset_of_explicit_fields() -> None:
    v = GenerateConfig.vanilla()
    assert v.critic is None and v.scene.placement == "naive" and not v.scene.check and v.mode == "vanilla"
    assert GenerateConfig().mode == "vcage"
    # fields given to the preset are kept as given, nothing is rewritten
    mixed = GenerateConfig.vanilla(critic=CriticConfig("oracle"))
    assert mixed.critic == CriticConfig("oracle") and mixed.scene.placement == "naive"


@pytest.mark.parametrize("build, match", [
    (lambda: RenderConfig(cameras=("front", "ceiling")), "unknown camera"),
    (lambda: RenderConfig(size=(800, 800)), "at most the renderer's 640x480"),
    (lambda: RenderConfig(size=(63, 64)), "even"),
    (lambda: RenderConfig(cameras=()), "at least one camera"),
    (lambda: GenerateConfig(seed=-1), "seed"),
    (lambda: GenerateConfig(seed=2**32), "seed"),
    (lambda: GenerateConfig(max_attempts=0), "max_attempts"),
    (lambda: SceneConfig(clutter=-1), "clutter"),
    (lambda: ExecutorConfig(workers=0), "workers"),
    (lambda: CriticConfig("vlm", votes=0), "votes"),
    (lambda: GenerateConfig.from_dict({"seed": 1, "colour": "red"}), "unknown GenerateConfig keys"),
])
def test_invalid_values_are_refused_when_built(build, match: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError, match=match):
        build()


def test_unknown_names_list_the_valid_ones() -> None:
    with pytest.raises(RegistryError, match=r"unknown critic 'psychic'; valid names: .*image.*oracle.*vlm"):
        CriticConfig("psychic")
    with pytest.raises(RegistryError, match="valid names: llm, offline"):
        PlannerConfig("oracle")
    with pytest.raises(RegistryError, match="context, naive, rejection"):
        SceneConfig("magic")


def test_render_cameras_are_the_cameras_every_scene_has() -> None:
    from vcage.scene.compose import compose
    from vcage.scene.spec import SceneSpec

    model = compose(SceneSpec()).model
    assert {model.camera(i).name for i in range(model.ncam)} == set(CAMERAS)


def test_endpoints_are_resolved_from_the_environment_once(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("VCAGE_VLM_MODEL", "qwen-vl")
    monkeypatch.setenv("VCAGE_VLM_BASE_URL", "http://localhost:8000/v1")
    monkeypatch.setenv("VCAGE_VLM_API_KEY", "sk-secret")
    cfg = GenerateConfig(critic=CriticConfig("vlm")).resolved()
    assert cfg.critic is not None and cfg.critic.backend is not None
    assert (cfg.critic.backend.model, cfg.critic.backend.api_key_env) == ("qwen-vl", "VCAGE_VLM_API_KEY")
    assert "sk-secret" not in json.dumps(cfg.to_dict())
    given = BackendConfig(base_url="http://localhost:9/v1", model="mine")
    kept = replace(cfg, critic=CriticConfig("vlm", given)).resolved()
    assert kept.critic is not None and kept.critic.backend == given  # the environment is a fallback
    monkeypatch.delenv("VCAGE_LLM_MODEL", raising=False)
    with pytest.raises(ConfigError, match="VCAGE_LLM_MODEL"):
        GenerateConfig(planner=PlannerConfig("llm")).resolved()
    assert GenerateConfig().resolved() == GenerateConfig()  # offline defaults need nothing


def test_noslip_is_off_by_default_and_an_older_stored_config_keeps_its_three_passes() -> None:
    from vcage.config import SimConfig
    from vcage.scene.compose import compose
    from vcage.scene.spec import SceneSpec

    assert SimConfig().noslip_iterations == 0
    older = {"timestep": 0.002, "control_hz": 20.0, "max_qvel": 100.0}  # stored before the field existed
    assert SimConfig.from_dict(older).noslip_iterations == 3
    assert SimConfig.from_dict({"timestep": 0.002}).noslip_iterations == 0  # partial: the defaults
    assert SimConfig.from_dict({**older, "noslip_iterations": 1}).noslip_iterations == 1
    with pytest.raises(ConfigError, match="noslip_iterations"):
        SimConfig(noslip_iterations=-1)
    for passes in (0, 3):
        assert compose(SceneSpec(), SimConfig(noslip_iterations=passes)).model.opt.noslip_iterations == passes
