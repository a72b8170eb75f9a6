"""One configuration tree on the command line: presets, files, endpoints; stored, never the key."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from backends.fake_openai import FakeOpenAI
from vcage.cli import app
from vcage.data import DatasetReader
from vcage.data.layout import VCAGE_PATH
from vcage.errors import ConfigError

RUN = CliRunner()
SMALL = ["--clutter", "1", "--size", "64"]
YES = json.dumps({"success": True, "reason": "the bell was pressed"})


@pytest.mark.parametrize("args", [["--cameras", "front,ceiling"], ["--size", "800"], ["--size", "63"],
                                  ["--seed", "-1"], ["--clutter", "-2"], ["--votes", "0"],
                                  ["--mode", "vanilla", "--critic-model", "m"]])
def test_bad_options_are_refused_before_anything_is_written(tmp_path: Path, args: list[str]) -> None:
    out = tmp_path / "ds"
    result = RUN.invoke(app, ["generate", "press the bell", "--out", str(out), *args])
    assert result.exit_code == 2 and result.output.startswith("error:"), (args, result.output)
    assert not out.exists()


def test_a_stored_config_reproduces_the_run_and_options_override_it(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    made = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                            "--mode", "vanilla", "--seed", "5", *SMALL])
    assert made.exit_code == 0, made.output
    stored = json.loads((out / VCAGE_PATH).read_text())["config"]["generate"]
    assert stored["critic"] is None and stored["scene"]["placement"] == "naive" and stored["seed"] == 5
    # the dataset's own file is a complete configuration: appending with it is accepted
    again = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                             "--config", str(out / VCAGE_PATH)])
    assert again.exit_code == 0, again.output
    assert DatasetReader(out).num_episodes == 2
    assert DatasetReader(out).extras(1)["seed"] != DatasetReader(out).extras(0)["seed"]
    # an option on top of the file changes the configuration, so the append is refused
    other = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                             "--config", str(out / VCAGE_PATH), "--seed", "6"])
    assert other.exit_code == 2 and "different configuration" in " ".join(other.output.split())


def test_the_vlm_endpoint_is_stored_with_the_data_and_the_key_never(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    secret = "sk-test-never-on-disk-0123456789"
    monkeypatch.setenv("VCAGE_VLM_API_KEY", secret)
    out = tmp_path / "ds"
    with FakeOpenAI("fake-vlm") as server:
        server.script(*([YES] * 4))
        made = RUN.invoke(app, ["generate", "press the bell", "--episodes", "1", "--out", str(out),
                                "--critic", "vlm", "--critic-url", server.base_url,
                                "--critic-model", "fake-vlm", "--votes", "1", *SMALL])
    assert made.exit_code == 0, made.output
    critic = json.loads((out / VCAGE_PATH).read_text())["config"]["generate"]["critic"]
    assert critic["name"] == "vlm" and critic["backend"]["model"] == "fake-vlm"
    assert critic["backend"]["base_url"] == server.base_url
    assert "api_key" not in critic["backend"]
    assert "timeout" not in critic["backend"]  # how it is reached is not compared when appending
    full = DatasetReader(out).extras(0)["config"]["critic"]["backend"]  # every episode: the whole tree
    assert full["api_key_env"] == "VCAGE_VLM_API_KEY" and full["timeout"] == 30.0 and "api_key" not in full
    for path in out.rglob("*"):
        if path.is_file():
            assert secret.encode() not in path.read_bytes(), path


def test_timeouts_and_retries_are_options_and_override_a_config_file(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from vcage.cli.generate import build_config

    monkeypatch.setenv("VCAGE_VLM_MODEL", "env-model")
    cfg = build_config(None, "vcage", {("critic", "name"): "vlm"},
                       {"critic": ("VCAGE_VLM", {"timeout": 2.5, "max_retries": 0})})
    assert cfg.critic is not None and cfg.critic.backend is not None
    assert (cfg.critic.backend.model, cfg.critic.backend.timeout, cfg.critic.backend.max_retries) == \
        ("env-model", 2.5, 0)
    path = tmp_path / "cfg.json"
    path.write_text(json.dumps(cfg.to_dict()))
    monkeypatch.delenv("VCAGE_VLM_MODEL")  # the file's endpoint is used, not the environment's
    again = build_config(path, "vcage", {}, {"critic": ("VCAGE_VLM", {"timeout": 9.0})})
    assert again.critic is not None and again.critic.backend is not None
    assert (again.critic.backend.model, again.critic.backend.timeout, again.critic.backend.max_retries) == \
        ("env-model", 9.0, 0)
    with pytest.raises(ConfigError, match="timeout"):
        build_config(path, "vcage", {}, {"critic": ("VCAGE_VLM", {"timeout": -1.0})})


def test_a_server_that_lists_no_models_is_used_with_the_preflight_off(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Found on 2026-12-05: a server that answers chat but not ``GET /models`` could not be used at
    all; the check before any work is now an option (and ``$VCAGE_VLM_PREFLIGHT``)."""
    from backends.fake_openai import Status

    args = ["generate", "press the bell", "--episodes", "1", "--critic", "vlm", "--critic-model", "fake-vlm",
            "--votes", "1", "--critic-retries", "0", *SMALL]
    with FakeOpenAI("fake-vlm") as server:
        server.listing_error = Status(404, "no such route")
        server.script(*([YES] * 4))
        refused = RUN.invoke(app, [*args, "--out", str(tmp_path / "a"), "--critic-url", server.base_url])
        assert refused.exit_code == 4 and not (tmp_path / "a").exists(), refused.output
        made = RUN.invoke(app, [*args, "--out", str(tmp_path / "b"), "--critic-url", server.base_url,
                                "--no-critic-preflight"])
        assert made.exit_code == 0, made.output
        monkeypatch.setenv("VCAGE_VLM_PREFLIGHT", "0")
        server.script(*([YES] * 4))
        again = RUN.invoke(app, [*args, "--out", str(tmp_path / "c"), "--critic-url", server.base_url])
        assert again.exit_code == 0, again.output
    critic = json.loads((tmp_path / "b" / VCAGE_PATH).read_text())["config"]["generate"]["critic"]
    assert critic["name"] == "vlm" and "preflight" not in critic["backend"]  # how it is reached: not compared
