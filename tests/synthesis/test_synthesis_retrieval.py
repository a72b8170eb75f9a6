"""Retrieval ranks the right catalog type for paraphrases and answers "no match" for negatives."""

from __future__ import annotations

import pytest

from vcage.assets.catalog import CATALOG
from vcage.errors import ConfigError
from vcage.synthesis.bm25 import BM25
from vcage.synthesis.retrieval import affords, retriever
from vcage.synthesis.text import edit_distance, misspells

PARAPHRASES = [
    ("a coffee mug", "mug"), ("loaf of bread", "bread"), ("a cellphone", "phone"), ("the hamper", "basket"),
    ("kleenex", "tissue_box"), ("jam", "jar"), ("a cardboard carton", "box"), ("an ink pad", "stamp_mat"),
    ("a pedestal", "object_stand"), ("a saucepan", "pot"), ("the clicker", "remote"), ("a bananna", "banana"),
    ("tangerine", "orange"), ("a soda", "can"), ("a die", "dice"), ("rubber stamp", "seal"),
]
NEGATIVES = ["a giraffe", "the laptop", "quantum physics", "a thing", "", "!!!",
             "a pineapple", "a keyboard", "a pair of scissors"]  # n-grams alone, or a generic word


@pytest.mark.parametrize(("query", "expected"), PARAPHRASES)
def test_paraphrases_rank_the_right_type_first(query: str, expected: str) -> None:
    assert retriever().search(query).best == expected


@pytest.mark.parametrize("query", NEGATIVES)
def test_negatives_are_answered_no_match(query: str) -> None:
    result = retriever().search(query)
    assert not result.found and result.no_match


def test_affordance_filters_keep_only_types_that_can() -> None:
    holders = retriever().search("a container to hold bread", k=10, require=("container",))
    containers = {t.name for t in CATALOG.values() if affords(t, "container")}  # the catalog grows
    assert {"basket", "bowl", "box", "cup", "mug", "pen_holder", "pot", "tray"} <= containers
    assert holders.found and set(holders.names()) <= containers and "bread" not in holders.names()
    grasp = retriever().search("a plate", require=("grasp",))
    assert "plate" not in grasp.names()  # plates carry no grasp annotation
    with pytest.raises(ConfigError, match="unknown affordance"):
        retriever().search("a mug", require=("fly",))


def test_bm25_idf_is_never_negative() -> None:
    index = BM25([["mug"], ["mug"], ["mug", "cup"]])
    assert all(v > 0 for v in index.idf.values())
    assert index.scores({"cup": 1.0})[2] > 0 and index.scores({"mug": 1.0})[0] > 0


def test_misspellings_are_within_one_edit_per_four_letters() -> None:
    assert edit_distance("bananna", "banana", 2) == 1 and edit_distance("kitten", "sitting", 5) == 3
    assert edit_distance("pineapple", "apple", 2) == 3  # beyond the limit: limit + 1
    assert misspells("stappler", ["stapler"]) and misspells("mugg", ["mug"])
    assert not misspells("pineapple", ["apple"]) and not misspells("keyboard", ["board"])
    assert retriever().search("a stappler").best == "stapler"
