"""What a prompt asks for, read from its words: the objects it names (with counts, colours and sizes),
the relations it states between them and the objects it negates.

Both describers answer to it. The offline one builds its objects from it and refuses a negation
(a scene is made of what it holds); an LLM's choice and description are checked against it
(:func:`unmet_in_choice`, :func:`unmet_in_description`), so that a model cannot drop an object, a
count or a relation, or bring in an object the prompt excludes, without the run saying so.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from vcage.planning.language import bounded
from vcage.planning.lexicon import Mention
from vcage.synthesis.description import MAX_OBJECTS, OPPOSITE, SceneDescription, SceneObject
from vcage.synthesis.errors import PromptError
from vcage.synthesis.prompt import explicit_relations, lexicon_mentions

NEGATIONS = frozenset({"no", "not", "without", "except", "never", "nor", "none", "dont", "nothing"})
NUMBERS = {"two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9,
           "ten": 10, "eleven": 11, "twelve": 12}
SYMMETRIC = frozenset({"near", "aligned"})


@dataclass(frozen=True)
class AskedObject:
    """``count`` objects of ``type`` (of ``color`` where the prompt gives one); ``phrase`` its words."""

    type: str
    color: str | None
    count: int
    scale: float
    phrase: str

    def label(self) -> str:
        return f"{self.color} {self.type}" if self.color else self.type

    def covers(self, obj: SceneObject) -> bool:
        return obj.type == self.type and (self.color is None or obj.color == self.color)


@dataclass(frozen=True)
class AskedRelation:
    """``kind`` between every object of group ``a`` and one of group ``b`` (indices into objects)."""

    kind: str
    a: int
    b: int


@dataclass(frozen=True)
class Asked:
    objects: tuple[AskedObject, ...]
    relations: tuple[AskedRelation, ...]
    negated: tuple[AskedObject, ...]

    def relation_text(self, r: AskedRelation) -> str:
        return f"{r.kind}({self.objects[r.a].label()}, {self.objects[r.b].label()})"

    def summary(self) -> str:
        """The request in one line, for a model's instructions."""
        parts = [f"{o.count} x {o.label()}" for o in self.objects]
        parts += [self.relation_text(r) for r in self.relations]
        parts += [f"no {o.label()}" for o in self.negated]
        return "; ".join(parts)


def read_prompt(text: str) -> Asked:
    """One group per mention (``count`` objects after a number: "three apples"), except that "the X"
    after an X names that X again ("a mouse pad behind a mouse, a cup right of the mouse pad" has
    one mouse pad). A mention with a negation among the two words before it is negated, not asked
    for. A relation of an object to itself, or a count over what a scene holds, is a
    :class:`PromptError`."""
    ws, mentions = lexicon_mentions(text)
    objects: list[AskedObject] = []
    negated: list[AskedObject] = []
    which: list[int | None] = []  # mention -> its group (None: negated)
    for m in mentions:
        color = m.colours[0] if len(m.colours) == 1 else None
        if _negated(ws, m):
            which.append(None)
            negated.append(AskedObject(m.type, color, 0, m.size or 1.0, _phrase(ws, m, negation=True)))
            continue
        again = _antecedent(ws, m, mentions[:len(which)], which, objects)
        if again is not None:
            which.append(again)
            continue
        which.append(len(objects))
        objects.append(AskedObject(m.type, color, _count(ws, m), m.size or 1.0, _phrase(ws, m)))
    relations: list[AskedRelation] = []
    for r in explicit_relations(ws, mentions):
        a, b = which[r.a], which[r.b]
        if a is None or b is None:  # "no apple in the bowl": nothing to place
            continue
        if a == b:
            raise PromptError(f"the prompt {bounded(text)} puts {objects[a].label()} {r.kind} itself; "
                              "name two objects for a relation")
        relations.append(AskedRelation(r.kind, a, b))
    return Asked(tuple(objects), tuple(relations), tuple(negated))


def _start(m: Mention) -> int:
    return m.first if m.first >= 0 else m.start


def _phrase(ws: list[str], m: Mention, negation: bool = False) -> str:
    """The mention's words with the one before it (its count or article), or from its negation on."""
    start = _start(m)
    if negation:
        return " ".join(ws[next(i for i in range(max(0, start - 2), start) if _negation(ws[i])):m.end])
    return " ".join(ws[max(0, start - 1):m.end])


def _negation(word: str) -> bool:
    return word in NEGATIONS or word.endswith("n't")


def _negated(ws: list[str], m: Mention) -> bool:
    start = _start(m)
    return any(_negation(w) for w in ws[max(0, start - 2):start])


def _count(ws: list[str], m: Mention) -> int:
    """How many objects the mention asks for: the number word or digits just before it, else one."""
    start = _start(m)
    word = ws[start - 1] if start > 0 else ""
    n = int(word) if word.isdigit() else NUMBERS.get(word, 1)
    if n > MAX_OBJECTS:
        raise PromptError(f"the prompt asks for {n} {m.noun}; a scene holds at most {MAX_OBJECTS} objects")
    return max(n, 1)


def _antecedent(ws: list[str], m: Mention, before: list[Mention], which: list[int | None],
                objects: list[AskedObject]) -> int | None:
    """The group an earlier mention made that the definite ``m`` names again, if exactly one fits."""
    if m.first <= 0 or ws[m.first - 1] != "the" or m.plural:
        return None
    fits = set()
    for k, e in enumerate(before):
        g = which[k]
        if g is not None and e.type == m.type and (not m.colours or objects[g].color in m.colours):
            fits.add(g)
    return fits.pop() if len(fits) == 1 else None


def unmet_in_choice(asked: Asked, chosen: Sequence[tuple[str, int]]) -> list[str]:
    """What a choice of ``(type, count)`` leaves out of the request, or brings in against it."""
    have = Counter({t: c for t, c in chosen})
    want: Counter[str] = Counter()
    for o in asked.objects:
        want[o.type] += o.count
    out = [f"the prompt asks for {n} x {t}; the choice has {have[t]}" for t, n in want.items() if have[t] < n]
    out += [f"the prompt says {o.phrase!r}; the choice has {o.type}" for o in asked.negated
            if o.color is None and have[o.type] > 0]
    return out


def unmet_in_description(asked: Asked, desc: SceneDescription) -> list[str]:
    """Every object, count, negation and relation of the request that ``desc`` does not honour."""
    out = []
    for t in dict.fromkeys(o.type for o in asked.objects):
        groups = [o for o in asked.objects if o.type == t]
        have = [x for x in desc.objects if x.type == t]
        if len(have) < sum(o.count for o in groups):
            out.append(f"the prompt asks for {sum(o.count for o in groups)} x {t}; the description has "
                       f"{len(have)}")
        for o in groups:
            if o.color is not None and sum(o.covers(x) for x in have) < o.count:
                out.append(f"the prompt asks for {o.count} x {o.label()} ({o.phrase!r}); the description "
                           f"has {sum(o.covers(x) for x in have)}")
    for o in asked.negated:
        there = [x.name for x in desc.objects if o.covers(x)]
        if there:
            out.append(f"the prompt says {o.phrase!r}; the description has {', '.join(there)}")
    for r in asked.relations:
        a, b = asked.objects[r.a], asked.objects[r.b]
        related = {x.a for x in desc.relations if x.kind == r.kind and _covers(desc, a, x.a)
                   and _covers(desc, b, x.b)}
        back = OPPOSITE.get(r.kind, r.kind if r.kind in SYMMETRIC else None)
        related |= {x.b for x in desc.relations if x.kind == back and _covers(desc, a, x.b)
                    and _covers(desc, b, x.a)}
        if len(related) < a.count:
            whom = f"each of the {a.count}" if a.count > 1 else "the"
            out.append(f"the prompt asks for {asked.relation_text(r)}: {whom} {a.label()} {r.kind} a "
                       f"{b.label()}; the description relates {len(related)} so")
    return out


def _covers(desc: SceneDescription, group: AskedObject, name: str) -> bool:
    return any(x.name == name and group.covers(x) for x in desc.objects)
