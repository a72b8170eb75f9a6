"""``vcage synthesize`` end to end: every artefact written; bad input gives typed errors (exit 2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.scene.spec import SceneSpec

RUN = CliRunner()


def test_synthesize_writes_every_artefact(tmp_path: Path) -> None:
    out = tmp_path / "syn"
    result = RUN.invoke(app, ["synthesize", "organize the breakfast table", "--out", str(out), "--seed", "1",
                              "--no-reach"])
    assert result.exit_code == 0, result.output
    for name in ("retrieval.json", "scene_description.json", "funnel.json", "scene_spec.json"):
        assert (out / name).is_file(), name
    attempt = sorted(out.glob("attempt-*"))[-1]
    for name in ("I_init.png", "I_goal.png", "empty_table.png", "matches.json", "refined_poses.json",
                 "goal_truth.json"):
        assert (attempt / name).is_file(), name
    spec = SceneSpec.from_dict(json.loads((out / "scene_spec.json").read_text()))
    assert {o.type for o in spec.objects} == {"bread", "basket", "cup", "coaster", "bell"}
    funnel = json.loads((out / "funnel.json").read_text())
    assert funnel[-1]["stage"] == "settle" and funnel[-1]["status"] == "ok"
    retrieval = json.loads((out / "retrieval.json").read_text())
    assert retrieval["prompt"]["hits"] and "score" in retrieval["prompt"]["hits"][0]


@pytest.mark.parametrize(("prompt", "message"), [
    ("", "empty"), ("?!", "no words"), ("put the giraffe next to the laptop", "catalog lacks"),
    ("put the frying pan next to the plate", "'frying pan', which the catalog lacks"),
    ("put the pot in the cup", "too large"),
])
def test_bad_prompts_are_typed_errors(tmp_path: Path, prompt: str, message: str) -> None:
    out = tmp_path / "bad"
    result = RUN.invoke(app, ["synthesize", prompt, "--out", str(out), "--no-reach"])
    assert result.exit_code == 2, result.output
    assert result.output.startswith("error:") and message in result.output
    if "catalog lacks" in message or message == "too large":  # what was written before the refusal stays
        funnel = json.loads((out / "funnel.json").read_text())
        assert funnel[-1]["status"] == "rejected" and (out / "retrieval.json").is_file()
