"""``vcage subtasks verify|list|show`` end to end, and its errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from backends.fake_openai import FakeOpenAI
from vcage.cli import app
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.store import SubtaskStore

RUN = CliRunner()


def test_verify_list_and_show(tmp_path: Path) -> None:
    db = str(tmp_path / "s.db")
    spec = SceneSpec(objects=(ObjectSpec("cube", "block", (0.45, -0.12), color="red"),
                              ObjectSpec("dish", "plate", (0.55, 0.12))))
    (tmp_path / "scene_spec.json").write_text(json.dumps(spec.to_dict()))
    done = RUN.invoke(app, ["subtasks", "verify", "task:press_stapler", str(tmp_path), "--db", db,
                            "--trials", "1", "--critic", "oracle"])
    assert done.exit_code == 0, done.output
    assert "press the stapler (press): SR 1.00 > 0.5 (1/1)" in done.output
    assert "put the block on the plate: SR 1.00 > 0.5 (1/1)" in done.output
    assert "funnel: candidates 2, valid 2, ran 2, succeeded 2, accepted 2" in done.output
    listed = RUN.invoke(app, ["subtasks", "list", "--db", db, "--status", "accepted"])
    assert listed.exit_code == 0 and listed.output.count("accepted") == 2
    with SubtaskStore(db, readonly=True) as store:
        ids = [r.id for r in store.subtasks()]
    assert all(i in listed.output for i in ids)
    first = ids[0]
    shown = RUN.invoke(app, ["subtasks", "show", first[:10], "--db", db])  # a unique prefix
    assert shown.exit_code == 0, shown.output
    data = json.loads(shown.output)
    assert data["id"] == first and len(data["trial_log"]) == 1
    assert data["trial_log"][0]["outcome"] == "success"
    sft = RUN.invoke(app, ["subtasks", "export-sft", str(tmp_path / "sft"), "--db", db, "--eval-share", "0"])
    assert sft.exit_code == 0, sft.output
    assert "train: 2 examples of 2 tasks; eval: 0 examples" in sft.output
    assert len((tmp_path / "sft" / "train.jsonl").read_text().splitlines()) == 2


def test_errors_are_one_line_and_exit_code_2(tmp_path: Path) -> None:
    bad = tmp_path / "bad.db"
    bad.write_bytes(b"garbage" * 200)
    cases = {
        ("list", "--db", str(bad)): "not a readable SQLite database",
        ("list", "--db", str(tmp_path / "none.db")): "no subtask database at",
        ("verify", "task:no_such_task", "--db", str(tmp_path / "s.db")): "unknown task 'no_such_task'",
        ("verify", str(tmp_path / "nowhere.json"), "--db", str(tmp_path / "s.db")): "is neither a task",
        ("show", "ffff", "--db", str(bad)): "move it aside",
        ("verify", "task:press_stapler", "--only", "fly", "--db", str(tmp_path / "s.db")): "--only 'fly'",
        ("verify", "goal:nope", "--db", str(tmp_path / "s.db")): "unknown goal 'nope'; goals: get_ready",
        ("verify", "goal:tidy_the_desk@x", "--db", str(tmp_path / "s.db")): "after '@' must be an integer",
    }
    for args, message in cases.items():
        result = RUN.invoke(app, ["subtasks", *args])
        assert result.exit_code == 2, (args, result.output)
        flat = " ".join(result.output.split())
        assert result.output.startswith("error: ") and message in flat, result.output
    assert not (tmp_path / "s.db").exists()  # nothing is written before the input is checked


def test_verify_with_a_model_writing_the_programs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    db = str(tmp_path / "s.db")
    with FakeOpenAI("coder") as server:
        server.script("```python\nimport os\n```", "```python\npress(obj='stapler', point='press')\n```")
        monkeypatch.setenv("VCAGE_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("VCAGE_LLM_MODEL", "coder")
        done = RUN.invoke(app, ["subtasks", "verify", "task:press_stapler", "--db", db, "--llm",
                                "--trials", "1", "--critic", "oracle"])
    assert done.exit_code == 0, done.output
    assert len(server.requests) == 2  # one repair after the import was refused
    with SubtaskStore(db, readonly=True) as store:
        (record,) = store.subtasks()
    assert (record.source, record.model, record.status) == ("llm", "coder", "accepted")
    assert record.code == "press(obj='stapler', point='press')\n" and len(record.prompt_hash or "") == 64
    monkeypatch.delenv("VCAGE_LLM_MODEL")
    missing = RUN.invoke(app, ["subtasks", "verify", "task:press_stapler", "--db", db, "--llm"])
    assert missing.exit_code == 2 and "VCAGE_LLM_MODEL" in missing.output


def test_a_goal_scene_is_the_goals_objects_placed_for_its_seed() -> None:
    from vcage.pipeline.scene_refs import resolve
    from vcage.planning.goals import GOALS

    a, spec = resolve("goal:get_ready_for_work@1")
    again, _ = resolve("goal:get_ready_for_work@1")
    other, _ = resolve("goal:get_ready_for_work@2")
    assert a == again and a.id != other.id and a.source == "goal:get_ready_for_work@1"
    goal = next(g for g in GOALS if g.name == "get_ready_for_work")
    assert sorted(o.name for o in spec.objects) == sorted(o.name for o in goal.objects)  # no clutter
