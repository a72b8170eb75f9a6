"""Tokens for retrieval: words, a light stemmer, stop words, synonym expansion, character n-grams."""

from __future__ import annotations

import re
from collections.abc import Iterable

from vcage.synthesis.synonyms import GENERIC, SYNONYMS, TOPICS

STOP = frozenset("""
a an the my our your his her their its this that these those to for of and or please can could
would you will i we me us it be is are get go do just now then with at by let lets in on into
onto from as
""".split())  # noqa: SIM905
SYNONYM_WEIGHT = 1.0  # a word's own synonyms count fully
TOPIC_WEIGHT = 0.5  # a theme's suggestions count half


def stem(word: str) -> str:
    """A light suffix stemmer (plural and verb endings), the same for queries and documents."""
    if word.endswith("ies") and len(word) > 4:
        return word[:-3] + "y"
    if word.endswith(("sses", "xes", "ches", "shes")):
        return word[:-2]
    for suffix in ("ing", "ed", "es", "s"):
        if word.endswith(suffix) and len(word) - len(suffix) >= 3 and not word.endswith("ss"):
            return word[: -len(suffix)]
    return word


def words(text: str) -> list[str]:
    """Lower-case alphanumeric words (``rubik's`` -> ``rubiks``)."""
    return re.findall(r"[a-z0-9]+", text.lower().replace("'", "").replace("\u2019", ""))


def tokens(text: str) -> list[str]:
    """Stemmed content words of ``text`` (stop words dropped)."""
    return [stem(w) for w in words(text) if w not in STOP]


def _groups(table: Iterable[tuple[str, str]]) -> dict[str, list[str]]:
    """variant (stemmed word or joined phrase) -> canonical stemmed tokens."""
    out: dict[str, list[str]] = {}
    for canon, variants in table:
        toks = [stem(w) for w in canon.split()]
        for v in variants.split():
            key = "_".join(stem(p) for p in v.split("_"))
            out.setdefault(key, []).extend(t for t in toks if t not in out.get(key, []))
    return out


_SYN = _groups(SYNONYMS)
_TOPIC = _groups(TOPICS)
GENERIC_STEMS = frozenset(stem(w) for w in GENERIC)


def expand(text: str) -> dict[str, float]:
    """Weighted query tokens: the text's own words (1.0), their synonyms' canonical words (1.0)
    and the words their themes suggest (0.5); multi-word variants ("ink pad") are read too."""
    toks = tokens(text)
    weights: dict[str, float] = {}

    def add(tok: str, w: float) -> None:
        weights[tok] = max(weights.get(tok, 0.0), w)

    for t in toks:
        add(t, 1.0)
    grams = toks + [f"{a}_{b}" for a, b in zip(toks, toks[1:], strict=False)]
    for g in grams:
        for c in _SYN.get(g, ()):
            add(c, SYNONYM_WEIGHT)
        for c in _TOPIC.get(g, ()):
            add(c, TOPIC_WEIGHT)
    return weights


def content(text: str) -> list[str]:
    """The words of ``text`` that could name an object: not stop words, not generic."""
    return [t for t in tokens(text) if t not in GENERIC_STEMS and not t.isdigit()]


def char_ngrams(text: str, n: tuple[int, ...] = (3, 4)) -> list[str]:
    """Character n-grams of each word padded with spaces (``" mug "`` -> `` mu``, ``mug``, ``ug ``)."""
    out: list[str] = []
    for w in words(text):
        if w in STOP:
            continue
        padded = f" {w} "
        for k in n:
            out.extend(padded[i:i + k] for i in range(max(1, len(padded) - k + 1)))
    return out


def edit_distance(a: str, b: str, limit: int) -> int:
    """Levenshtein distance of ``a`` and ``b``, or ``limit + 1`` once it is known to exceed ``limit``."""
    if abs(len(a) - len(b)) > limit:
        return limit + 1
    row = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        prev, row[0] = row[0], i
        best = row[0]
        for j, cb in enumerate(b, 1):
            prev, row[j] = row[j], min(row[j] + 1, row[j - 1] + 1, prev + (ca != cb))
            best = min(best, row[j])
        if best > limit:
            return limit + 1
    return row[-1]


def misspells(word: str, vocabulary: Iterable[str]) -> bool:
    """Whether ``word`` is a misspelling of a vocabulary word: within one edit per four letters (at
    least one), so "bananna" is banana but "pineapple" is not apple nor "keyboard" board."""
    limit = max(1, len(word) // 4)
    return any(edit_distance(word, v, limit) <= limit for v in vocabulary)
