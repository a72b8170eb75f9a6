"""The model proposes subtasks of its own: a real local OpenAI-compatible server replays its answers;
invalid proposals are sent back item by item, repeats of known subtasks are dropped, the kept ones
are verified in MuJoCo like any model-written code."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from backends.fake_openai import FakeOpenAI
from vcage.backends import BackendConfig, connect
from vcage.cli import app
from vcage.errors import SubtaskError
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.candidates import candidates
from vcage.subtasks.proposals import SubtaskProposer
from vcage.subtasks.store import SubtaskStore

SCENE = SceneSpec(objects=(ObjectSpec("cube", "block", (0.45, -0.12), color="red"),
                           ObjectSpec("dish", "plate", (0.55, 0.12)),
                           ObjectSpec("bell", "bell", (0.6, -0.1))))
RUN = CliRunner()


def item(skill: str, args: dict, description: str, *preds: tuple[str, list[str]]) -> dict:
    return {"skill": skill, "args": args, "description": description,
            "predicates": [{"name": n, "args": a} for n, a in preds]}


BESIDE = item("pick_and_place", {"obj": "cube", "xy": [0.45, 0.25]}, "put the cube left of the dish",
              ("left_of", ["cube", "dish"]), ("released", ["cube"]))
KNOWN = item("pick_and_place", {"obj": "cube", "target": "dish"}, "put the cube on the dish",
             ("on", ["cube", "dish"]), ("released", ["cube"]))


def answer(*items: dict) -> str:
    return "```json\n" + json.dumps({"subtasks": list(items)}) + "\n```"


def _proposer(server: FakeOpenAI, limit: int = 5) -> SubtaskProposer:
    return SubtaskProposer(connect(BackendConfig(base_url=server.base_url, model="planner-x", max_retries=0)),
                           limit)


def test_valid_proposals_are_kept_and_repeats_of_known_subtasks_dropped() -> None:
    known = candidates("s", SCENE)
    with FakeOpenAI("planner-x") as server:
        server.script(answer(BESIDE, KNOWN, BESIDE))
        got, counts = _proposer(server).propose("s", SCENE, known)
    assert [c.description for c in got] == ["put the cube left of the dish"]
    assert counts.to_dict() == {"replies": 1, "proposed": 3, "valid": 1, "duplicates": 2, "invalid": 0}
    (cand,) = got
    assert (cand.template, cand.source, cand.model) == ("proposed", "llm", "planner-x")
    assert cand.code == "pick_and_place(obj='cube', xy=[0.45, 0.25])\n" and len(cand.prompt_hash or "") == 64
    prompt = server.requests[0]["messages"]
    assert "dish: a plate at x=0.550" in prompt[1]["content"] and "on placement 'top'" in prompt[1]["content"]
    assert "put the block on the plate: pick_and_place" in prompt[1]["content"]  # the known ones, to avoid


def test_invalid_proposals_are_sent_back_until_fixed_or_given_up() -> None:
    off_table = item("pick_and_place", {"obj": "cube", "xy": [3.0, 0.0]}, "throw the cube away",
                     ("released", ["cube"]))
    ghost = item("press", {"obj": "lamp", "point": "button"}, "press the lamp", ("pressed", ["lamp"]))
    silent = item("press", {"obj": "bell", "point": "button"}, "press the bell", ("upright", ["dish"]))
    bell = item("press", {"obj": "bell", "point": "button"}, "ring the bell", ("pressed", ["bell"]))
    with FakeOpenAI("planner-x") as server:
        server.script("I would put the cube on the plate.",  # prose
                      answer(off_table, ghost, BESIDE),
                      answer(silent, bell))
        got, counts = _proposer(server).propose("s", SCENE, candidates("s", SCENE))
        second, third = server.requests[1]["messages"], server.requests[2]["messages"]
    assert "not valid JSON" in second[-1]["content"]
    assert "subtask 0:" in third[-1]["content"] and "off the table" in third[-1]["content"]
    assert "subtask 1:" in third[-1]["content"]
    assert "'lamp' is not an object of the scene" in third[-1]["content"]
    assert [c.description for c in got] == ["put the cube left of the dish"]  # the press repeats a known one
    assert counts.invalid == 1 and "no predicate says anything about 'bell'" in counts.problems[0]
    assert counts.duplicates == 1 and counts.replies == 3


def test_the_cap_holds_and_a_bad_cap_is_refused() -> None:
    with FakeOpenAI("planner-x") as server:
        other = item("pick_and_place", {"obj": "cube", "xy": [0.5, 0.25]}, "move the cube left",
                     ("released", ["cube"]))
        server.script(answer(BESIDE, other))
        got, counts = _proposer(server, limit=1).propose("s", SCENE, [])
        assert len(got) == 1 and counts.valid == 1
        with pytest.raises(SubtaskError, match=">= 1"):
            _proposer(server, limit=0)


def test_verify_proposes_checks_and_stores_the_models_subtasks(tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    db = str(tmp_path / "s.db")
    (tmp_path / "scene_spec.json").write_text(json.dumps(SCENE.to_dict()))
    with FakeOpenAI("planner-x") as server:
        server.script(answer(BESIDE, KNOWN))
        monkeypatch.setenv("VCAGE_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("VCAGE_LLM_MODEL", "planner-x")
        done = RUN.invoke(app, ["subtasks", "verify", str(tmp_path), "--db", db, "--propose", "3", "--only",
                                "press", "--trials", "1", "--critic", "oracle"])
    assert done.exit_code == 0, done.output
    flat = " ".join(done.output.split())
    assert "proposed 2 subtask(s) in 1 replies: 1 kept, 1 repeating known ones" in flat
    with SubtaskStore(db, readonly=True) as store:
        rows = {r.description: r for r in store.subtasks()}
    assert set(rows) == {"press the bell (button)", "put the cube left of the dish"}
    proposed = rows["put the cube left of the dish"]
    assert (proposed.source, proposed.model, proposed.status) == ("llm", "planner-x", "accepted")
    assert proposed.predicates == ("left_of(cube, dish)", "released(cube)")
