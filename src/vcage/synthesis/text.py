"""Tokens for retrieval: words, a light stemmer, stop words, synonym expansion, the head noun of a
phrase, character n-grams."""

from __future__ import annotations

import re
from collections.abc import Iterable

from vcage.synthesis.synonyms import GENERIC, QUANTITIES, SYNONYMS, TOPICS

STOP = frozenset("""
a an the my our your his her their its this that these those to for of and or please can could
would you will i we me us it be is are get go do just now then with at by let lets in on into
onto from as
""".split())  # noqa: SIM905
# words that end the first noun phrase of a description ("a glass of wine", "a tray to carry cups")
PHRASE_END = frozenset("""
of for with to that which who whose where on in into onto inside from at by under over beside near
and or than like you i we they he she it someone
""".split())  # noqa: SIM905
DETERMINERS = frozenset("a an the some its their my your his her this these those".split())  # noqa: SIM905
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
QUANTITY_STEMS = frozenset(stem(w) for w in QUANTITIES)


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


def head(text: str) -> tuple[str, ...] | None:
    """The stemmed head noun of the first noun phrase of ``text``, after the word before it if any
    (a compound such as "drink mat" may be a synonym as a whole).

    The head is the last word before the first word that ends the phrase ("a frying pan" -> pan,
    "a glass of wine" -> glass, "a tray to carry cups" -> tray); a participle after a noun ends it
    too ("a board showing a code" -> board). A generic head or an amount defers to the phrase after
    "of" ("a pair of headphones", "a pack of cards"); None when there is none ("the red one",
    "something to write with").
    """
    phrase: list[str] = []
    ws = [*words(text), ""]
    for i, w in enumerate(ws):
        named = [stem(x) for x in phrase if x not in STOP and not x.isdigit()]
        participle = w.endswith("ing") and bool(named) and ws[i + 1] in DETERMINERS  # "showing a code"
        if w and w not in PHRASE_END and not participle:
            phrase.append(w)
            continue
        if named and named[-1] not in GENERIC_STEMS and named[-1] not in QUANTITY_STEMS:
            return tuple(named[-2:])
        if w != "of":
            return None
        phrase = []
    return None


def names_of(noun: tuple[str, ...]) -> set[str]:
    """What a head noun (from :func:`head`) names: itself, its synonyms' canonical words, and those
    of the compound it ends ("drink mat" -> coaster); never the modifier alone, nor themes."""
    out = {noun[-1], *_SYN.get(noun[-1], ())}
    if len(noun) > 1:
        out.update(_SYN.get("_".join(noun), ()))
    return out


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
