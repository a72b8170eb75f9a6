"""SFT export split by task, and the code-generation evaluation against a replaying local server."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from backends.fake_openai import FakeOpenAI
from vcage.backends import BackendConfig, connect
from vcage.sandbox import check
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.calls import api
from vcage.subtasks.candidates import candidates
from vcage.subtasks.evaluate import sample_programs, score, table
from vcage.subtasks.records import SceneRecord, SubtaskRecord
from vcage.subtasks.scenes import resolve, scene_id
from vcage.subtasks.sft import export_sft, in_eval
from vcage.subtasks.stats import wilson
from vcage.subtasks.store import SubtaskStore

SPECS = [SceneSpec(objects=(ObjectSpec("cube", "block", (0.45, -0.12)),
                            ObjectSpec("dish", "plate", (0.55, 0.12)),
                            ObjectSpec("cup", "cup", (0.4, 0.25)), ObjectSpec("bin", "basket", (0.6, -0.3)))),
         SceneSpec(objects=(ObjectSpec("apple", "apple", (0.45, 0.1)),
                            ObjectSpec("tray", "tray", (0.6, -0.1))))]


def test_sft_export_splits_by_task_and_keeps_only_verified_programs(tmp_path: Path) -> None:
    db = tmp_path / "s.db"
    with SubtaskStore(db) as store:
        for i, spec in enumerate(SPECS):
            sid = scene_id(spec)
            store.add_scene(SceneRecord(sid, f"test{i}", spec.to_dict()))
            for c in candidates(sid, spec):
                wins = 1 if c.args["obj"] == "cup" else 3  # as if every cup subtask failed verification
                store.put(SubtaskRecord(c.id, sid, c.skill, dict(c.args), c.description,
                                        tuple(str(p) for p in c.predicates), c.code, c.code_hash, c.source, 3,
                                        wins, wins / 3, *wilson(wins, 3),
                                        "accepted" if wins == 3 else "rejected", "stored by the test"), [])
        counts = export_sft(store, tmp_path / "sft", eval_share=0.5)
    train = [json.loads(x) for x in (tmp_path / "sft" / "train.jsonl").read_text().splitlines()]
    held = [json.loads(x) for x in (tmp_path / "sft" / "eval.jsonl").read_text().splitlines()]
    assert counts.train == len(train) > 0 and counts.eval == len(held) > 0
    assert set(counts.train_tasks).isdisjoint(counts.eval_tasks)
    assert {e["metadata"]["task"] for e in held} == set(counts.eval_tasks)
    assert all(in_eval(e["metadata"]["task"], 0.5) for e in held)
    examples = train + held
    assert not any("obj='cup'" in e["completion"][0]["content"] for e in examples)  # rejected: not taught
    assert any("target='cup'" in e["completion"][0]["content"] for e in examples)
    for e in examples:
        assert [m["role"] for m in e["prompt"]] == ["system", "user"]
        assert e["completion"][0]["role"] == "assistant"
        check(e["completion"][0]["content"], [s.name for s in api()])  # every completion is a valid program
    split = json.loads((tmp_path / "sft" / "split.json").read_text())
    assert split == {"eval": list(counts.eval_tasks), "train": list(counts.train_tasks)}


REPLAYS = {
    "good": "```python\npress(obj='stapler', point='press')\n```",
    "buggy": "```python\np = position('stapler')\npress(obj='stapler', point=p[5])\n```",  # IndexError
    "near-miss": "```python\npush(obj='stapler', direction=(1.0, 0.0), distance=0.05)\n```",
    "malicious": "```python\nimport os\nos.system('rm -rf /')\n```",
    "prose": "To do this, move the gripper above the stapler and push down firmly.",
}


def test_the_evaluation_harness_scores_replayed_completions() -> None:
    scene, spec = resolve("task:press_stapler")
    (cand,) = candidates(scene.id, spec)
    with FakeOpenAI() as server:
        server.script(*REPLAYS.values())
        backend = connect(BackendConfig(base_url=server.base_url, model="fake-model", max_retries=0))
        programs = sample_programs(backend, cand, spec, n=len(REPLAYS))
    assert len(server.requests) == 5
    model = score(cand, spec, programs, seeds=1, model="fake-model")
    assert model.rates == (1.0, 0.0, 0.0, 0.0, 0.0)
    assert model.avg_sr == pytest.approx(0.2) and model.top3_sr == pytest.approx(1 / 3)
    assert model.pass_at(1) == pytest.approx(0.2) and model.pass_at(3) == pytest.approx(0.6)
    assert model.pass_at(5) == 1.0
    assert model.failures == {"runtime_error": 1, "oracle": 1, "rejected": 2}
    reference = score(cand, spec, [cand.program_text()] * 2, seeds=1)
    assert reference.rates == (1.0, 1.0) and reference.pass_at(1) == 1.0 and reference.pass_at(3) is None
    text = table([("reference", reference), ("fake-model", model)])
    assert "fake-model | press the stapler (press) | 5 | 1 | 0.200 | 0.333 | 0.200 | 0.600 | 1.000" in text
