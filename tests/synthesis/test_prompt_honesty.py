"""The offline describer never changes the request without a word (found on 2026-12-05: a prompt
naming 40 objects gave 12 with exit 0; "a table with no apple" put an apple in; counts and
relations of an object to itself were dropped): every object, count, negation and relation is
either in the description or named in a refusal."""

from __future__ import annotations

import pytest

from vcage.synthesis.describe import describe
from vcage.synthesis.description import MAX_OBJECTS
from vcage.synthesis.errors import PromptError

NOUNS = ["apple", "banana", "mug", "plate", "book", "bell", "stapler", "mouse", "cup", "bowl", "marker",
         "soap", "lemon", "orange", "seal"]


@pytest.mark.parametrize("prompt", ["a table with no apple", "a plate without a mug", "a bowl but not a cup",
                                    "a desk with a mouse and no mouse pad"])
def test_a_negated_object_is_refused_not_put_in(prompt: str) -> None:
    with pytest.raises(PromptError, match="name only the objects it should hold"):
        describe(prompt)


def test_more_objects_than_a_table_holds_is_refused_not_cut() -> None:
    prompt = ", ".join(f"a {n}" for n in NOUNS)
    with pytest.raises(PromptError, match=rf"names 1\d objects; a scene holds at most {MAX_OBJECTS}"):
        describe(prompt)
    with pytest.raises(PromptError, match="asks for 40 apple"):
        describe("40 apples on a table")


def test_a_count_gives_that_many_objects_each_in_the_relation() -> None:
    desc, _ = describe("two apples on a plate and a mug")
    apples = [o.name for o in desc.objects if o.type == "apple"]
    assert len(apples) == 2 and any(o.type == "mug" for o in desc.objects)
    on = {(r.a, r.b) for r in desc.relations if r.kind == "on"}
    plate = next(o.name for o in desc.objects if o.type == "plate")
    assert {(a, plate) for a in apples} <= on


def test_a_relation_of_an_object_to_itself_is_refused() -> None:
    with pytest.raises(PromptError, match="on itself"):
        describe("a mug on the mug")


def test_a_plain_list_is_taken_as_it_is() -> None:
    desc, source = describe("a mug, a plate and a book")
    assert source.kind == "mentions" and sorted(o.type for o in desc.objects) == ["book", "mug", "plate"]
