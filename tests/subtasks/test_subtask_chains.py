"""Long-horizon chains composed from verified subtasks: the chaining rules, a seeded draw, the
rebuild from a dataset's record, the scene generation starts from, and `vcage generate --subtasks`
end to end in MuJoCo."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest
from typer.testing import CliRunner

from vcage.cli import app
from vcage.errors import SceneError, SubtaskStoreError
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.chains import SceneFacts, SubtaskChain, compatible, compose, rebuild, scene_of
from vcage.subtasks.records import SceneRecord, SubtaskRecord
from vcage.subtasks.store import SubtaskStore

RUN = CliRunner()
TOP = 0.75  # the default table's top
SPEC = SceneSpec(objects=(
    ObjectSpec("a", "block", (0.45, -0.15), color="red", z=TOP),
    ObjectSpec("b", "block", (0.45, 0.0), z=TOP),
    ObjectSpec("c", "block", (0.45, 0.15), color="blue", z=TOP),
    ObjectSpec("plate", "plate", (0.6, 0.1), z=TOP),
    ObjectSpec("bell", "bell", (0.6, -0.1), z=TOP)))
SCENE = SceneRecord("sceneabcdef0", "task:test@0", SPEC.to_dict())


def put(obj: str, target: str, status: str = "accepted", source: str = "template") -> SubtaskRecord:
    return _record(f"put{obj}{target}", "pick_and_place", {"obj": obj, "target": target},
                   f"put the {obj} on the {target}", (f"on({obj}, {target})", f"released({obj})"),
                   status, source)


def press(obj: str) -> SubtaskRecord:
    return _record(f"press{obj}", "press", {"obj": obj, "point": "button"}, f"press the {obj}",
                   (f"pressed({obj})", f"upright({obj})"))


def _record(key: str, skill: str, params: dict, text: str, preds: tuple[str, ...], status: str = "accepted",
            source: str = "template") -> SubtaskRecord:
    return SubtaskRecord(id=f"{key:0>16}"[-16:], scene_id=SCENE.id, skill=skill, parameters=params,
                         description=text, predicates=preds,
                         code=json.dumps([{"skill": skill, "args": params}]),
                         code_hash="ab" * 32, source=source, trials=10, successes=9, success_rate=0.9,
                         ci_low=0.6, ci_high=0.98, status=status, reason="SR 0.90 > 0.5")


def _store(path: Path, records: list[SubtaskRecord], scene: SceneRecord = SCENE) -> Path:
    with SubtaskStore(path) as store:
        store.add_scene(scene)
        for r in records:
            store.put(r, [])
    return path


NONE = SceneFacts()


def test_a_step_may_not_undo_or_repeat_what_the_chain_did() -> None:
    a_on_b, c_on_b = put("a", "b"), put("c", "b")
    b_on_plate, a_on_plate = put("b", "plate"), put("a", "plate")
    assert compatible([], a_on_b, NONE)
    assert not compatible([a_on_b], a_on_b, NONE)  # the same step twice
    assert not compatible([a_on_b], a_on_plate, NONE)  # a moved twice
    assert not compatible([a_on_b], c_on_b, NONE)  # b receives a second object
    assert not compatible([a_on_b], b_on_plate, NONE)  # b would carry a away
    assert compatible([a_on_b], put("c", "a"), NONE)  # a tower: a moved, then a target
    assert compatible([a_on_b], press("bell"), NONE)
    assert not compatible([press("bell")], press("bell"), NONE)
    assert not compatible([], a_on_plate, SceneFacts(frozenset({"plate"})))  # holds something at the start


def test_compose_draws_the_same_chain_for_the_same_seed(tmp_path: Path) -> None:
    records = [put("a", "b"), put("c", "b"), put("a", "plate"), put("c", "plate"), press("bell"),
               put("b", "plate", status="rejected"), put("c", "a", source="llm")]
    db = _store(tmp_path / "s.db", records)
    with SubtaskStore(db, readonly=True) as store:
        chains = {seed: compose(store, 3, seed) for seed in range(8)}
        again = compose(store, 3, 5)
    assert again.provenance == chains[5].provenance and again.plan == chains[5].plan
    assert len({c.provenance.subtasks for c in chains.values()}) > 1  # the seed matters
    allowed = {r.id for r in records[:5]}  # accepted templates only
    for chain in chains.values():
        steps = list(chain.records)
        assert {r.id for r in steps} <= allowed and len(steps) == 3
        assert all(compatible(steps[:i], steps[i], NONE) for i in range(3))
        assert chain.plan.instruction == ", then ".join(r.description for r in steps)
        assert [st.skill for st in chain.plan.subtasks] == [r.skill for r in steps]
        assert [str(p) for st in chain.plan.subtasks for p in st.predicates] == \
            [p for r in steps for p in r.predicates]
        assert {o.name for o in chain.plan.objects} == {"a", "b", "c", "plate", "bell"}
        assert chain.scene.editor == "subtasks" and str(chain.scene.source).endswith(f"#{SCENE.id}")


def test_a_chain_longer_than_the_rules_allow_is_refused_with_the_longest(tmp_path: Path) -> None:
    db = _store(tmp_path / "s.db", [put("a", "b"), put("c", "b"), press("bell")])
    with SubtaskStore(db, readonly=True) as store:
        assert len(compose(store, 2, 0).records) == 2
        with pytest.raises(SubtaskStoreError, match=f"no chain of 3 .*{SCENE.id}: 2.*shorter --chain"):
            compose(store, 3, 0)
        with pytest.raises(SubtaskStoreError, match="no scene 'nosuchscene'"):
            compose(store, 2, 0, "nosuchscene")
    empty = _store(tmp_path / "e.db", [put("a", "b", status="rejected")])
    with SubtaskStore(empty, readonly=True) as store, \
            pytest.raises(SubtaskStoreError, match="no accepted template subtask"):
        compose(store, 1, 0)


def test_rebuild_makes_the_recorded_chain_and_refuses_a_changed_database(tmp_path: Path) -> None:
    records = [put("a", "b"), put("c", "plate"), press("bell")]
    db = _store(tmp_path / "s.db", records)
    with SubtaskStore(db, readonly=True) as store:
        chain = compose(store, 3, 1)
        stored = SubtaskChain.from_dict(json.loads(json.dumps(chain.provenance.to_dict())))
        assert rebuild(store, stored).plan == chain.plan
    first = next(r for r in records if r.id == chain.provenance.subtasks[0])
    with SubtaskStore(db) as store:
        store.put(replace(first, status="rejected"), [])
    with SubtaskStore(db, readonly=True) as store, \
            pytest.raises(SubtaskStoreError, match="no longer an accepted"):
        rebuild(store, stored)


def test_the_scene_knows_what_rests_on_what(tmp_path: Path) -> None:
    stacked = SceneSpec(objects=(ObjectSpec("basket", "basket", (0.5, 0.0), z=TOP),
                                 ObjectSpec("bread", "bread", (0.51, 0.01), z=TOP + 0.008),
                                 ObjectSpec("cup", "cup", (0.6, 0.2), z=TOP)))
    scene = scene_of(SceneRecord("s1", "task:x@0", stacked.to_dict()))
    assert {o.name: o.on for o in scene.objects} == {"basket": None, "bread": "basket", "cup": None}
    floating = SceneSpec(objects=(ObjectSpec("cup", "cup", (0.6, 0.2), z=TOP + 0.05),))
    with pytest.raises(SceneError, match="rests above the table but on no object"):
        scene_of(SceneRecord("s2", "task:x@0", floating.to_dict()))
    # a basket that holds bread at the start is no target of a chain
    db = _store(tmp_path / "s.db", [_record("k", "pick_and_place", {"obj": "cup", "target": "basket"},
                                            "put the cup in the basket", ("inside(cup, basket)",))],
                scene=SceneRecord(SCENE.id, "task:x@0", stacked.to_dict()))
    with SubtaskStore(db, readonly=True) as store, pytest.raises(SubtaskStoreError, match="no chain of 1"):
        compose(store, 1, 0)


@pytest.mark.slow
def test_generate_runs_a_chain_of_verified_subtasks(tmp_path: Path) -> None:
    db, out = str(tmp_path / "s.db"), tmp_path / "ds"
    spec = SceneSpec(objects=(ObjectSpec("cube", "block", (0.5, -0.12), color="red"),
                              ObjectSpec("dish", "plate", (0.58, 0.12)),
                              ObjectSpec("bell", "bell", (0.62, -0.05))))
    (tmp_path / "scene_spec.json").write_text(json.dumps(spec.to_dict()))
    done = RUN.invoke(app, ["subtasks", "verify", str(tmp_path), "--db", db, "--trials", "1",
                            "--critic", "oracle"])
    assert done.exit_code == 0, done.output
    shown = RUN.invoke(app, ["subtasks", "chain", "--db", db, "--length", "2"])
    assert shown.exit_code == 0, shown.output
    assert "1. " in shown.output and "2. " in shown.output and "pressed(bell)" in shown.output
    made = RUN.invoke(app, ["generate", "--subtasks", db, "--chain", "2", "--episodes", "1",
                            "--out", str(out), "--clutter", "1", "--size", "64", "--cameras", "front"])
    assert made.exit_code == 0, made.output
    meta = json.loads((out / "meta" / "vcage.json").read_text())
    chain, plan = meta["config"]["generate"]["chain"], meta["config"]["plan"]
    assert chain["db"] == str(Path(db).resolve()) and len(chain["subtasks"]) == 2
    assert {st["skill"] for st in plan["subtasks"]} == {"pick_and_place", "press"}
    assert meta["config"]["generate"]["synthesized"]["editor"] == "subtasks"
    audit = RUN.invoke(app, ["audit", str(out)])
    assert audit.exit_code == 0 and "label noise 0.0%" in audit.output, audit.output
    # the run's configuration rebuilds the same chain from the ids it recorded: the dataset takes
    # another episode of it (appending checks that the configuration is the same)
    (tmp_path / "cfg.json").write_text(json.dumps(meta))
    again = RUN.invoke(app, ["generate", "--config", str(tmp_path / "cfg.json"), "--episodes", "2", "--total",
                             "--out", str(out)])
    assert again.exit_code == 0 and "holds 2 episodes" in " ".join(again.output.split()), again.output


def test_generate_wants_an_instruction_or_a_database_not_both(tmp_path: Path) -> None:
    db = _store(tmp_path / "s.db", [put("a", "b")])
    cases = {(): "give an INSTRUCTION", ("press the bell", "--subtasks", str(db)): "no INSTRUCTION",
             ("--subtasks", str(tmp_path / "none.db")): "no subtask database at"}
    for args, message in cases.items():
        result = RUN.invoke(app, ["generate", *args, "--out", str(tmp_path / "ds")])
        assert result.exit_code == 2 and message in result.output, (args, result.output)
        assert not (tmp_path / "ds").exists()
