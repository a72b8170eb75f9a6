"""Small, deterministic language tools for the offline planner: tokens, synonyms, similarity.

Words are lower-cased, stripped of punctuation, reduced by a light suffix stemmer and mapped to a
canonical synonym, so that "tidy up my desk", "clean the desk" and "organising the workspace"
share tokens. Similarity is an IDF-weighted overlap of token sets. ``bounded`` quotes user text in
error messages without repeating more than ``QUOTE_LIMIT`` characters of it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass

QUOTE_LIMIT = 200  # characters of user text an error message may repeat


def bounded(text: str, limit: int = QUOTE_LIMIT) -> str:
    """``text`` quoted for a message: whole if short, else its start, an ellipsis and its length."""
    if len(text) <= limit:
        return repr(text)
    return f"{text[:limit] + '...'!r} ({len(text)} characters, the first {limit} shown)"

_STOP_WORDS = """
a an the my our your his her their its this that these those to for of and or please can could
would you will i we me us it be is are get go do some all just now then up down with at by let
lets want need like
d m s ll re ve t"""  # the pieces contractions leave ("i'd", "i'm", "it's", "we'll", "don't")
STOP = frozenset(_STOP_WORDS.split())

# canonical word <- variants (after stemming)
SYNONYMS: dict[str, tuple[str, ...]] = {
    "tidy": ("tidy", "clean", "organis", "organiz", "declutter", "neaten", "clear", "straighten"),
    "prepare": ("prepar", "make", "fix", "ready", "readi", "setup", "arrang"),
    "breakfast": ("breakfast", "brunch", "morning meal"),
    "desk": ("desk", "workspac", "workstat", "office", "desktop"),
    "work": ("work", "job", "workday", "day"),
    "colour": ("colour", "color", "hue"),
    "sort": ("sort", "order", "rank", "group"),
    "tower": ("tower", "stack", "pile", "heap"),
    "table": ("table", "dinner", "meal", "lunch", "supper"),
    "off": ("off", "shut", "down", "close", "leav", "night"),
    "fruit": ("fruit", "fruits", "apple", "orange"),
    "display": ("display", "show", "exhibit", "present"),
    "tea": ("tea", "drink", "beverag", "coffe"),
    "kitchen": ("kitchen", "dish", "bowl", "counter"),
    "paperwork": ("paperwork", "paper", "document", "stamp", "stapl"),
    "block": ("block", "cube", "brick"),
}


def stem(word: str) -> str:
    if word.endswith(("sses", "xes", "zes", "ches", "shes")):
        word = word[:-2]
    for suffix in ("ing", "ies", "ed", "s", "e"):
        if word.endswith(suffix) and len(word) - len(suffix) >= 3:
            return word[: -len(suffix)] + ("y" if suffix == "ies" else "")
    return word


_CANON = {form: k for k, vs in SYNONYMS.items() for v in vs for form in (v, stem(v))}


def tokens(text: str) -> list[str]:
    """Canonical content tokens of ``text``."""
    words = re.findall(r"[a-z0-9]+", text.lower().replace("set up", "setup"))
    out = []
    for w in words:
        if w in STOP:
            continue
        s = stem(w)
        out.append(_CANON.get(s, _CANON.get(w, s)))
    return out


@dataclass(frozen=True)
class Scored:
    """A label's score for a text, and the text's tokens its best phrasing shares (the evidence)."""

    label: str
    score: float
    evidence: frozenset[str]


class Matcher:
    """Scores a text against labelled phrasings by IDF-weighted token overlap (0..1)."""

    def __init__(self, labelled: Iterable[tuple[str, str]]) -> None:
        self.entries = [(label, set(tokens(text))) for label, text in labelled]
        df: dict[str, int] = {}
        for _, toks in self.entries:
            for t in toks:
                df[t] = df.get(t, 0) + 1
        n = max(1, len(self.entries))
        self.idf = {t: math.log(1 + n / c) for t, c in df.items()}
        self.default_idf = math.log(1 + n)

    def _w(self, tok: str) -> float:
        return self.idf.get(tok, self.default_idf)

    @property
    def vocabulary(self) -> frozenset[str]:
        """Every token of every phrasing."""
        return frozenset(t for _, toks in self.entries for t in toks)

    def vocabulary_of(self, label: str) -> frozenset[str]:
        return frozenset(t for lab, toks in self.entries if lab == label for t in toks)

    def rank(self, text: str) -> list[Scored]:
        """Every label scored, best first (ties by label); a label's score is its best phrasing's."""
        query = set(tokens(text))
        best: dict[str, Scored] = {}
        for label, toks in self.entries:
            union = query | toks
            if not union:
                continue
            shared = query & toks
            s = sum(self._w(t) for t in shared) / sum(self._w(t) for t in union)
            if label not in best or s > best[label].score:
                best[label] = Scored(label, s, frozenset(shared))
        return sorted(best.values(), key=lambda x: (-x.score, x.label))

    def score(self, text: str) -> list[tuple[float, str]]:
        """(score, label) for every label, best first; a label's score is its best phrasing's."""
        return sorted(((x.score, x.label) for x in self.rank(text)), reverse=True)
