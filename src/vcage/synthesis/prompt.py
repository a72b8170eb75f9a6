"""What a prompt names: a check that it says something, its noun phrases and explicit relations."""

from __future__ import annotations

import re
from dataclasses import dataclass

from vcage.planning.language import bounded
from vcage.planning.lexicon import DETERMINERS, Mention, determiner_phrases, find_mentions
from vcage.planning.lexicon import words as lexicon_words
from vcage.synthesis.errors import PromptError
from vcage.synthesis.text import tokens

MAX_PROMPT = 1000  # characters
# relation phrases between two named objects: "the apple in the bowl", "the cup left of the plate"
RELATION_PHRASES: tuple[tuple[str, str], ...] = (
    ("to the left of", "left_of"), ("left of", "left_of"), ("to the right of", "right_of"),
    ("right of", "right_of"), ("in front of", "in_front_of"), ("behind", "behind"),
    ("next to", "near"), ("beside", "near"), ("near", "near"), ("by", "near"),
    ("in line with", "aligned"), ("aligned with", "aligned"), ("inside", "inside"), ("into", "inside"),
    ("in", "inside"), ("onto", "on"), ("on top of", "on"), ("on", "on"),
)
STOPPERS = frozenset({"on", "in", "into", "onto", "inside", "with", "from", "of", "under", "near",
                      "beside", "by", "at", "over", "next", "behind", "and", "or", "then", "to", "left",
                      "right", "front", ",", "."})


def check_prompt(prompt: str) -> str:
    """The prompt with whitespace normalised; :class:`PromptError` if it says nothing."""
    text = " ".join(str(prompt).split())
    if not text:
        raise PromptError("the prompt is empty: describe the scene, e.g. 'organize the breakfast table'")
    if len(text) > MAX_PROMPT:
        raise PromptError(f"the prompt has {len(text)} characters, more than {MAX_PROMPT}: shorten it")
    if not re.search(r"[A-Za-z]{2,}", text) or not tokens(text):
        raise PromptError(f"the prompt {bounded(text)} has no words to build a scene from: describe the "
                          "scene, e.g. 'put the fruit on a plate'")
    return text


def lexicon_mentions(text: str) -> tuple[list[str], list[Mention]]:
    ws = lexicon_words(text)
    return ws, find_mentions(ws)


def noun_phrases(text: str) -> list[str]:
    """Phrases a determiner introduces ("the laptop", "a blue mug"), up to three words each."""
    return [" ".join(run) for _, run in determiner_phrases(lexicon_words(text), STOPPERS.__contains__)]


@dataclass(frozen=True)
class PhraseRelation:
    kind: str
    a: int  # index of the first mention
    b: int  # index of the second


def explicit_relations(ws: list[str], mentions: list[Mention]) -> list[PhraseRelation]:
    """Relations the words between two consecutive mentions state ("X ... left of ... Y")."""
    out = []
    for k in range(len(mentions) - 1):
        between = " ".join(w for w in ws[mentions[k].end:mentions[k + 1].first] if w not in DETERMINERS)
        between = f" {between} "
        for phrase, kind in RELATION_PHRASES:
            if f" {phrase} " in between:
                out.append(PhraseRelation(kind, k, k + 1))
                break
    return out
