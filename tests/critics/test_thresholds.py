"""The image critic's thresholds are a configuration: ``CriticConfig.thresholds`` overrides them by name,
the checks read the ones in force while the critic judges (never a value bound at import), the
critic's version tells an overridden critic from the default, and the configuration is stored with the
dataset only where it overrides something."""

from __future__ import annotations

import ast
import json
from dataclasses import fields
from pathlib import Path
from typing import Any

import pytest

from critics.recipes import HERE, observed
from vcage.cli.generate import build_config
from vcage.critics import image
from vcage.critics.base import CriticConfig, make_critic
from vcage.critics.image import ImageCritic
from vcage.critics.image.thresholds import DEFAULT, STRUCTURAL, Thresholds, active, values
from vcage.errors import ConfigError
from vcage.pipeline.config import GenerateConfig

NAMES = [f.name for f in fields(Thresholds)]
CRITIC = ImageCritic()
ROCKED = "clock-rocking-onto-a-marker"  # the hand read 6.0 mm past a full press: refused, too deep


def _bound_at_import(path: Path) -> list[str]:
    """Where the rule file ``path`` reads a threshold that an override would not reach: a name imported
    from the thresholds module other than a structural constant or the accessor, the defaults or a
    threshold read off the module, or the accessor called at import (outside any function)."""
    allowed = set(STRUCTURAL) | {"active"}
    tree = ast.parse(path.read_text())
    bound: list[str] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("thresholds"):
            bound += [f"{path.name}: imports {a.name}" for a in node.names if a.name not in allowed]
        elif isinstance(node, ast.Attribute) and node.attr in {*NAMES, "DEFAULT"} \
                and ast.unparse(node.value) in ("thresholds", "image.thresholds"):
            bound.append(f"{path.name}:{node.lineno}: {ast.unparse(node)}")
        elif isinstance(node, ast.Name) and node.id == "DEFAULT":
            bound.append(f"{path.name}:{node.lineno}: DEFAULT")
    for statement in tree.body:
        if not isinstance(statement, ast.FunctionDef | ast.ClassDef):
            bound += [f"{path.name}:{node.lineno}: active() at import" for node in ast.walk(statement)
                      if isinstance(node, ast.Call) and ast.unparse(node.func) == "active"]
    return bound


def test_no_rule_file_binds_a_threshold_at_import() -> None:
    """A check that imported a threshold by name (or read it at import, or off the defaults) would
    ignore an override; and the thresholds module holds no threshold as a module constant."""
    assert [line for path in image.rule_files() if path.name != "thresholds.py"
            for line in _bound_at_import(path)] == []
    assert not set(NAMES) & set(vars(image.thresholds)), "a threshold is also a module constant"


def test_the_import_check_sees_a_threshold_bound_at_import(tmp_path: Path) -> None:
    path = tmp_path / "check.py"
    path.write_text("from vcage.critics.image.thresholds import NEAR, TOP, active\n"
                    "from vcage.critics.image import thresholds\n"
                    "LIMIT = active().NEAR\n"
                    "def f(d):\n    return d > thresholds.NEAR or d > active().NEAR\n")
    assert _bound_at_import(path) == ["check.py: imports NEAR", "check.py:5: thresholds.NEAR",
                                      "check.py:3: active() at import"]


def test_judging_reads_every_threshold_from_the_critics_configuration() -> None:
    """Judged with a configuration that records what is read of it, the stored observations read every
    threshold from it: none comes from anywhere else (and none is left unused)."""
    read: set[str] = set()

    class Reading:
        def __getattr__(self, name: str) -> Any:
            read.add(name)
            return getattr(DEFAULT, name)

    critic = ImageCritic()
    critic.thresholds = Reading()  # type: ignore[assignment]
    for path in sorted(HERE.glob("*.npz")):
        critic.judge(observed(path.stem).obs)
    assert read == set(NAMES)
    assert active() is DEFAULT  # the judgement's thresholds are gone once it is done


def test_thresholds_given_their_default_values_change_no_verdict_and_no_version() -> None:
    same = make_critic(CriticConfig(thresholds={k: v for k, v in values().items() if k in NAMES}))
    assert same.version() == CRITIC.version() == f"image@{image.rules_digest()}"
    assert same.rules() == CRITIC.rules() == values()
    for path in sorted(HERE.glob("*.npz"))[::4]:
        obs = observed(path.stem).obs
        assert same.judge(obs).to_dict() == CRITIC.judge(obs).to_dict(), path.stem


def test_an_override_changes_a_verdict_and_the_default_gives_it_back() -> None:
    obs = observed(ROCKED).obs
    refused = CRITIC.judge(obs)
    assert not refused.accept and refused.codes == ("pressed.too_deep",), refused.reason
    roomy = make_critic(CriticConfig(thresholds={"PRESS_ROOM": 0.007}))  # 7 mm past a full press
    assert roomy.judge(obs).accept
    assert active() is DEFAULT
    assert CRITIC.judge(obs).to_dict() == refused.to_dict()


def test_the_version_and_the_rules_tell_an_overridden_critic_from_the_default() -> None:
    default = CRITIC.version()
    assert default == f"image@{image.rules_digest()}"
    near = ImageCritic({"NEAR": 0.12})
    assert near.version().startswith(default + "+") and near.version() != default
    assert ImageCritic({"NEAR": 0.12}).version() == near.version()
    assert ImageCritic({"NEAR": 0.13}).version() not in (near.version(), default)
    assert near.rules() == {**values(), "NEAR": 0.12}


@pytest.mark.parametrize(("given", "match"), [
    ({"NEARR": 0.1}, r"unknown image critic thresholds \['NEARR'\]; valid: MIN_OVERLAP, CENTRE_TOL"),
    ({"NEAR": "far"}, r"NEAR must be a value like its default 0.1 \(float\), got 'far'"),
    ({"NEAR": True}, "NEAR must be"),
    ({"NEAR": float("nan")}, "NEAR must be"),
    ({"LIFT_ROWS": 8.5}, r"LIFT_ROWS must be a value like its default 8 \(int\)"),
    ({"AREA_RATIO": [0.8]}, r"AREA_RATIO must be a value like its default \[0.8, 1.25\]"),
    ({"BUTTON_PX": [8.0, 24]}, "BUTTON_PX must be"),
    ({"TURNS": []}, "TURNS must be"),
    ({"PRESS_SHARE": {"button": 0.4}}, r"PRESS_SHARE must be a value like its default \{'button': 0.4"),
])
def test_an_unknown_threshold_or_a_value_not_of_its_kind_is_refused(given: dict[str, Any],
                                                                     match: str) -> None:
    with pytest.raises(ConfigError, match=match):
        CriticConfig(thresholds=given)
    with pytest.raises(ConfigError, match=match):
        GenerateConfig.from_dict({"critic": {"name": "image", "thresholds": given}})


def test_thresholds_are_refused_for_another_critic_and_must_be_a_mapping() -> None:
    with pytest.raises(ConfigError, match="thresholds apply to the image critic, not to 'vlm'"):
        CriticConfig("vlm", thresholds={"NEAR": 0.12})
    with pytest.raises(ConfigError, match="must map names to values"):
        CriticConfig.from_dict({"thresholds": ["NEAR", 0.12]})


def test_a_configuration_with_thresholds_round_trips_and_the_default_stores_none() -> None:
    cfg = CriticConfig(thresholds={"NEAR": 0.12, "SUPPORT_TOL": 0, "BUTTON_PX": (6, 30),
                                   "PRESS_SHARE": {"button": 0.3, "lever": 0.5}})
    stored = {"NEAR": 0.12, "SUPPORT_TOL": 0.0, "BUTTON_PX": [6, 30],
              "PRESS_SHARE": {"button": 0.3, "lever": 0.5}}
    assert cfg.to_dict()["thresholds"] == stored
    assert CriticConfig.from_dict(json.loads(json.dumps(cfg.to_dict()))) == cfg
    run = GenerateConfig(critic=cfg)
    again = GenerateConfig.from_dict(json.loads(json.dumps(run.to_dict())))
    assert again == run and hash(again) == hash(run) and again.critic is not None
    assert make_critic(again.critic).version() == ImageCritic(stored).version() != CRITIC.version()
    assert "thresholds" not in CriticConfig().to_dict()
    assert list(GenerateConfig().to_dict()["critic"]) == ["name", "backend", "votes", "rule",
                                                          "malformed_verdict"]
    assert CriticConfig.from_dict(CriticConfig().to_dict()) == CriticConfig()


def test_a_configuration_file_gives_the_thresholds_on_the_command_line(tmp_path: Path) -> None:
    path = tmp_path / "run.json"
    path.write_text(json.dumps({"critic": {"name": "image", "thresholds": {"PRESS_ROOM": 0.007}}}))
    cfg = build_config(path, "vcage", {("seed",): 3}, {})
    assert cfg.critic is not None and cfg.critic.thresholds == {"PRESS_ROOM": 0.007} and cfg.seed == 3
    assert cfg.to_dict()["critic"]["thresholds"] == {"PRESS_ROOM": 0.007}
