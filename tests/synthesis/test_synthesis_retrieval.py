"""Retrieval ranks the right catalog type for paraphrases and answers "no match" for negatives."""

from __future__ import annotations

import pytest

from vcage.assets.catalog import CATALOG
from vcage.errors import ConfigError
from vcage.synthesis.bm25 import BM25
from vcage.synthesis.retrieval import affords, retriever
from vcage.synthesis.text import edit_distance, head, misspells, stem

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


@pytest.mark.parametrize(("phrase", "noun"), [
    ("a frying pan", ("fry", "pan")), ("a glass of wine", ("glass",)), ("a tray to carry cups", ("tray",)),
    ("a pair of headphones", (stem("headphones"),)), ("a pack of playing cards", ("play", "card")),
    ("a board showing a QR code", ("board",)), ("a wooden rolling pin", ("roll", "pin")),
    ("a desk bell you ring for service", ("desk", "bell")), ("the red one", None),
    ("something to write with", None)])
def test_the_head_noun_is_the_last_word_of_the_first_noun_phrase(phrase: str, noun: tuple | None) -> None:
    assert head(phrase) == noun


@pytest.mark.parametrize("phrase", ["a frying pan", "a coffee machine", "a kitchen knife", "a glass of wine",
                                    "a bread knife", "a phone charger", "a toy robot"])
def test_a_phrase_whose_head_names_no_type_is_no_match(phrase: str) -> None:
    """The modifiers name catalog types (fries, mug, sponge, jar, bread, phone, toys): ranking by
    meaning finds them, naming does not."""
    assert retriever().search(phrase).found
    result = retriever().find(phrase)
    assert not result.found and repr(head(phrase)[-1]) in (result.no_match or "")


@pytest.mark.parametrize(("phrase", "expected"), [("a small toy brick", "block"), ("a drink mat", "coaster"),
                                                  ("a cheap cellphone", "phone"),
                                                  ("a pencil cup", "pen_holder")])
def test_types_the_head_names_come_first(phrase: str, expected: str) -> None:
    """Synonyms, compounds named as a whole ("drink mat") and closed compounds ("shoebox") name a type."""
    assert retriever().find(phrase).best == expected


def test_a_closed_compound_ending_in_a_types_name_names_it() -> None:
    assert "shoe_box" in retriever().find("an open shoebox").names()


def test_a_phrase_without_a_head_noun_is_ranked_by_meaning() -> None:
    assert retriever().find("something to drink from").names() == retriever().search(
        "something to drink from").names()
