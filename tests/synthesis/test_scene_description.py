"""D_scene validation refuses contradictions and what cannot fit; the offline describer and prompts."""

from __future__ import annotations

import pytest

from vcage.synthesis.describe import describe
from vcage.synthesis.description import parse_description
from vcage.synthesis.errors import PromptError, SceneDescriptionError

OBJECTS = [{"name": "a", "type": "apple"}, {"name": "p", "type": "plate"}, {"name": "c", "type": "cup"}]


def desc(relations: list[dict], objects: list[dict] | None = None) -> object:
    return parse_description({"prompt": "x", "text": "a scene", "objects": objects or OBJECTS,
                              "relations": relations})


def rel(kind: str, a: str, b: str, **kw: float) -> dict:
    return {"kind": kind, "a": a, "b": b, **kw}


def test_a_consistent_description_validates() -> None:
    d = desc([rel("on", "a", "p"), rel("left_of", "c", "p"), rel("aligned", "c", "p")])
    assert [o.name for o in d.table_objects()] == ["p", "c"]


@pytest.mark.parametrize(("relations", "message"), [
    ([rel("left_of", "a", "p"), rel("right_of", "a", "p")], "contradict"),
    ([rel("left_of", "a", "p"), rel("left_of", "p", "c"), rel("left_of", "c", "a")], "contradict"),
    ([rel("in_front_of", "a", "p"), rel("behind", "a", "p")], "contradict"),
    ([rel("on", "a", "p"), rel("inside", "a", "c")], "two supports"),
    ([rel("on", "a", "p"), rel("left_of", "a", "p")], "cannot also be beside"),
    ([rel("on", "p", "a")], "no surface"),
    ([rel("inside", "p", "c")], "too large"),
    ([rel("near", "a", "a")], "itself"),
    ([rel("on", "a", "ghost")], "unknown object"),
])
def test_contradictions_are_refused(relations: list[dict], message: str) -> None:
    with pytest.raises(SceneDescriptionError, match=message):
        desc(relations)


def test_descriptions_that_cannot_fit_are_refused() -> None:
    with pytest.raises(SceneDescriptionError, match="cover"):
        desc([], [{"name": f"p{i}", "type": "pot"} for i in range(8)])
    chain = [{"name": f"t{i}", "type": "apple"} for i in range(4)]
    with pytest.raises(SceneDescriptionError, match="chain"):
        desc([rel("left_of", f"t{i}", f"t{i + 1}", distance=0.4) for i in range(3)], chain)
    with pytest.raises(SceneDescriptionError, match="unknown object type"):
        desc([], [{"name": "g", "type": "giraffe"}])


def test_offline_description_from_the_goal_library_and_templates() -> None:
    d, source = describe("organize the breakfast table")
    assert source.kind == "goal:prepare_breakfast"
    kinds = {str(r) for r in d.relations}
    assert {"inside(bread, basket)", "on(cup, coaster)"} <= kinds
    assert any(r.kind == "left_of" for r in d.relations) and "bread" in d.text


def test_offline_description_reads_explicit_relations() -> None:
    d, source = describe("put the apple in the bowl and the cup left of the plate")
    assert source.kind == "mentions"
    assert {str(r) for r in d.relations} == {"inside(apple, bowl)", "left_of(cup, plate)"}


@pytest.mark.parametrize("prompt", ["", "   ", "!!! ???", "the giraffe"])
def test_empty_or_meaningless_prompts_are_typed_errors(prompt: str) -> None:
    with pytest.raises(PromptError):
        describe(prompt)


def test_an_impossible_prompt_is_a_description_error() -> None:
    with pytest.raises(SceneDescriptionError, match="too large"):
        describe("put the pot in the cup")


def test_the_names_an_object_again_and_a_names_a_new_one() -> None:
    desc, _ = describe("a mouse pad behind a mouse, a cup right of the mouse pad")
    assert [o.type for o in desc.objects] == ["mouse_pad", "mouse", "cup"]
    assert {str(r) for r in desc.relations} >= {"behind(mouse_pad, mouse)", "right_of(cup, mouse_pad)"}
    desc, _ = describe("a red block and a blue block, the red block left of the blue block")
    assert [o.name for o in desc.objects] == ["red_block", "blue_block"]
    assert "left_of(red_block, blue_block)" in {str(r) for r in desc.relations}
    desc, _ = describe("a mug next to a mug")  # no "the": two mugs
    assert [o.type for o in desc.objects] == ["mug", "mug"]


def test_a_list_of_objects_is_the_scene_and_pairs_only_what_goes_together() -> None:
    desc, source = describe("an apple, a bowl and a book")
    assert source.kind == "mentions" and [o.type for o in desc.objects] == ["apple", "bowl", "book"]
    assert "inside(apple, bowl)" in {str(r) for r in desc.relations}
    desc, _ = describe("a mug to the left of a mouse pad and a mouse")
    kinds = {str(r) for r in desc.relations}
    assert "on(mouse, mouse_pad)" in kinds and not any("mouse, mug" in k for k in kinds)  # never in a mug
    _, source = describe("tidy the desk with the mouse")  # one object named: the goal, with it
    assert source.kind == "goal:tidy_the_desk"
