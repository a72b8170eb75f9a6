"""Language-guided asset retrieval: rank the annotated catalog against a request by meaning.

Each catalog type is a document of its name, category, description, tags and affordances (what
can be grasped, what holds objects on or in it, what has a button or a switch). A request is
ranked by BM25 over synonym-expanded words and by character n-gram TF-IDF (for misspellings), and
the two rankings are fused by reciprocal rank. Affordance filters keep only types that can do what
the scene needs. A request whose words name nothing the catalog has gets an answer with no hits
and the reason: "no suitable object" is a result, not an error.

:meth:`Retriever.search` ranks a request by meaning, themes included ("serve tea" suggests cups).
:meth:`Retriever.find` answers a phrase that names one object ("a frying pan"): the type must be
what the phrase's head noun names (its name, category, tags or the head of its description, a
synonym or misspelling of one, or a closed compound ending in one: "cheeseburger"), so words
that only qualify the head ("frying pan", "coffee machine") do not make a match.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.errors import ConfigError
from vcage.synthesis.bm25 import BM25
from vcage.synthesis.text import (
    GENERIC_STEMS,
    char_ngrams,
    content,
    expand,
    head,
    misspells,
    names_of,
    tokens,
)
from vcage.synthesis.tfidf import CharTfidf

Affordance = Literal["grasp", "support", "container", "placement", "functional"]
AFFORDANCES: tuple[str, ...] = ("grasp", "support", "container", "placement", "functional")
RRF_K = 60  # reciprocal rank fusion constant (Cormack et al.)
NAME_REPEAT = 3  # a type's own name words count this many times in its document
TYPO_COSINE = 0.3  # without a shared word: a misspelling of one of its words, at least this n-gram cosine
MIN_COSINE = 0.1  # below this the n-gram ranking does not vote for a type
COMPOUND_MIN = 3  # letters of a naming word that may end a closed compound ("shoebox" -> box)


def affords(t: ObjectType, need: str) -> bool:
    if need == "grasp":
        return bool(t.grasps)
    if need == "support":
        return any(p.kind == "on" for p in t.placements)
    if need == "container":
        return any(p.kind == "in" for p in t.placements)
    if need == "placement":
        return bool(t.placements)
    if need == "functional":
        return bool(t.functional_points)
    raise ConfigError(f"unknown affordance {need!r}; valid: {', '.join(AFFORDANCES)}")


def document(t: ObjectType) -> str:
    """The words a type is found by."""
    parts = [" ".join([t.name.replace("_", " ")] * NAME_REPEAT), t.category, t.description,
             " ".join(sorted(t.tags))]
    if t.grasps:
        parts.append("graspable pick")
    for p in t.placements:
        parts.append("support surface holds objects on top" if p.kind == "on" else "container holds inside")
    for f in t.functional_points:
        parts.append(f"{f.kind} press functional")
    return " ".join(parts)


def naming_words(t: ObjectType) -> frozenset[str]:
    """The stems that name a type: its name, category, tags and the head of its description."""
    out = set(tokens(t.name.replace("_", " "))) | set(tokens(t.category)) | set(tokens(" ".join(t.tags)))
    described = head(t.description)
    if described is not None:
        out.add(described[-1])
    return frozenset(out)


@dataclass(frozen=True)
class Hit:
    type: str
    score: float  # fused reciprocal-rank score (higher is better)
    bm25: float
    cosine: float

    def to_dict(self) -> dict[str, object]:
        return {"type": self.type, "score": round(self.score, 5), "bm25": round(self.bm25, 4),
                "cosine": round(self.cosine, 4)}


@dataclass(frozen=True)
class Retrieval:
    """The answer to one request: hits best first, or none and the reason (``no_match``)."""

    query: str
    hits: tuple[Hit, ...] = ()
    no_match: str | None = None
    filters: tuple[str, ...] = field(default=())

    @property
    def found(self) -> bool:
        return bool(self.hits)

    @property
    def best(self) -> str | None:
        return self.hits[0].type if self.hits else None

    def names(self) -> list[str]:
        return [h.type for h in self.hits]

    def to_dict(self) -> dict[str, object]:
        return {"query": self.query, "filters": list(self.filters), "no_match": self.no_match,
                "hits": [h.to_dict() for h in self.hits]}


class Retriever:
    """Ranks catalog types against text; built once over the catalog (or any list of types)."""

    def __init__(self, types: list[ObjectType] | None = None) -> None:
        self.types = list(types) if types is not None else list(CATALOG.values())
        docs = [document(t) for t in self.types]
        self.words = [frozenset(tokens(d)) for d in docs]
        self.naming = {t.name: naming_words(t) for t in self.types}
        self.bm25 = BM25([tokens(d) for d in docs])
        self.tfidf = CharTfidf([char_ngrams(d) for d in docs])

    def search(self, query: str, k: int = 5, require: tuple[str, ...] = ()) -> Retrieval:
        """The ``k`` best types for ``query`` that afford everything in ``require``."""
        for need in require:
            affords(self.types[0], need)  # unknown affordances raise, even before matching
        if not content(query):
            return Retrieval(query, no_match="the request names no object (only stop words or generic "
                                             "words such as 'thing')", filters=require)
        weights = {t: w for t, w in expand(query).items()  # generic words ("pair", "top") say nothing
                   if t in self.bm25.vocabulary and t not in GENERIC_STEMS}
        bm = self.bm25.scores(weights) if weights else [0.0] * len(self.types)
        cos = self.tfidf.scores(char_ngrams(" ".join(content(query))))
        unknown = [w for w in content(query) if w not in self.bm25.vocabulary]

        def typo(i: int) -> bool:  # found by n-grams alone: only as a misspelling of its words
            return cos[i] >= TYPO_COSINE and any(misspells(w, self.words[i]) for w in unknown)

        keep = [i for i, t in enumerate(self.types)
                if all(affords(t, n) for n in require) and (bm[i] > 0 or typo(i))]
        if not keep:
            why = ("no catalog type affords " + ", ".join(require)) if require and (
                any(b > 0 for b in bm) or max(cos) >= TYPO_COSINE) else "no catalog type matches its words"
            return Retrieval(query, no_match=why, filters=require)
        rank_bm = sorted(keep, key=lambda i: (-bm[i], self.types[i].name))
        rank_cos = sorted(keep, key=lambda i: (-cos[i], self.types[i].name))
        fused = {i: 0.0 for i in keep}
        for r, i in enumerate(rank_bm):
            if bm[i] > 0:
                fused[i] += 1.0 / (RRF_K + r + 1)
        for r, i in enumerate(rank_cos):
            if cos[i] >= MIN_COSINE:
                fused[i] += 1.0 / (RRF_K + r + 1)
        order = sorted(keep, key=lambda i: (-fused[i], -bm[i], -cos[i], self.types[i].name))[:k]
        return Retrieval(query, tuple(Hit(self.types[i].name, fused[i], bm[i], cos[i]) for i in order),
                         filters=require)

    def find(self, phrase: str, k: int = 5, require: tuple[str, ...] = ()) -> Retrieval:
        """The ``k`` best types for ``phrase``, which names one object (see the module's docstring):
        no match unless its head noun names a type :meth:`search` finds; those it names come first,
        each group in :meth:`search`'s order. A phrase without a head noun ("something to write
        with") is ranked as :meth:`search` ranks it."""
        ranked = self.search(phrase, len(self.types), require)
        noun = head(phrase)
        if noun is None or not ranked.found:
            return Retrieval(ranked.query, ranked.hits[:k], ranked.no_match, ranked.filters)
        named = names_of(noun)
        grounded = [self._names(noun[-1], named, self.naming[h.type]) for h in ranked.hits]
        if not any(grounded):
            return Retrieval(phrase, no_match=f"no catalog type is a {noun[-1]!r} (its other words match "
                                              f"{', '.join(ranked.names()[:3])})", filters=require)
        hits = [h for h, g in zip(ranked.hits, grounded, strict=True) if g]
        hits += [h for h, g in zip(ranked.hits, grounded, strict=True) if not g]
        return Retrieval(phrase, tuple(hits[:k]), filters=require)

    @staticmethod
    def _names(noun: str, named: set[str], naming: frozenset[str]) -> bool:
        return bool(named & naming) or misspells(noun, naming) or any(
            len(w) >= COMPOUND_MIN and len(noun) > len(w) and noun.endswith(w) for w in naming)


_DEFAULT: Retriever | None = None


def retriever() -> Retriever:
    """The retriever over the whole catalog, built on first use."""
    global _DEFAULT
    if _DEFAULT is None:
        _DEFAULT = Retriever()
    return _DEFAULT
