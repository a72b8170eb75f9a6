"""The offline scene describer: a prompt to a :class:`SceneDescription` without any model.

Objects come, in this order of preference, from the catalog objects the prompt names (with the
relations it states between them, "the apple in the bowl"; a list of two or more objects is taken
as it is), from the best-matching goal of the planner's library (its objects; its subtasks'
``on`` / ``inside`` goals become relations; an object the prompt names joins them), or from
retrieval over the catalog. :mod:`vcage.synthesis.templates` arranges what the prompt leaves free.
"""

from __future__ import annotations

from dataclasses import dataclass

from vcage.planning.goals import GOALS, Goal
from vcage.planning.language import bounded
from vcage.planning.lexicon import Mention
from vcage.planning.offline import OfflinePlanner
from vcage.synthesis.description import MAX_OBJECTS, SceneDescription, SceneObject, SceneRelation
from vcage.synthesis.description import parse_description as _parse
from vcage.synthesis.errors import PromptError, SceneDescriptionError
from vcage.synthesis.prompt import check_prompt, explicit_relations, lexicon_mentions
from vcage.synthesis.retrieval import Retrieval
from vcage.synthesis.templates import image_text, pairing, row

GOAL_THRESHOLD = 0.25  # a goal this similar to the prompt lends its objects and relations
MAX_RETRIEVED = 4  # objects a scene takes from retrieval alone
LIST_OF_OBJECTS = 2  # a prompt naming this many objects and no relation is taken as the list of them
MIN_RETRIEVED_SCORE = 0.02  # fused score a retrieved type needs to join a scene (about rank <= 20 in both)


@dataclass(frozen=True)
class Source:
    """Where the description's objects came from: ``mentions``, ``goal:<name>`` or ``retrieval``."""

    kind: str
    score: float | None = None


def _unique(names: list[str], base: str) -> str:
    name, k = base, 2
    while name in names:
        name, k = f"{base}_{k}", k + 1
    return name


def _from_goal(goal: Goal) -> tuple[list[SceneObject], list[SceneRelation]]:
    objects = [SceneObject(name=o.name, type=o.type, color=o.color, scale=o.scale or 1.0)
               for o in goal.objects if o.type not in ("switch",)]
    names = {o.name for o in objects}
    relations = []
    for st in goal.subtasks:
        for p in st.predicates:
            if p.name in ("on", "inside") and set(p.args) <= names:
                relations.append(SceneRelation(kind=p.name, a=p.args[0], b=p.args[1]))  # type: ignore[arg-type]
    return objects, relations


def _from_mentions(text: str) -> tuple[list[SceneObject], list[SceneRelation]]:
    """One object per mention (``count`` of them after a number: "three apples"), except that "the
    X" after an X names that X again ("a mouse pad behind a mouse, a cup right of the mouse pad" has
    one mouse pad). A mention the prompt negates ("no apple") or a relation of an object to itself
    is refused: the scene would not be what was asked."""
    ws, mentions = lexicon_mentions(text)
    objects: list[SceneObject] = []
    which: list[int] = []  # mention -> object (its first, where a count made several)
    made: dict[int, range] = {}  # object -> the objects its mention made ("three apples": all three)
    for m in mentions:
        _refuse_negated(ws, m)
        color = m.colours[0] if len(m.colours) == 1 else None
        again = _antecedent(ws, m, mentions[:len(which)], which, objects)
        if again is not None:
            which.append(again)
            continue
        base = f"{color}_{m.type}" if color else m.type
        which.append(len(objects))
        made[len(objects)] = range(len(objects), len(objects) + _count(ws, m))
        for _ in made[len(objects)]:
            objects.append(SceneObject(name=_unique([o.name for o in objects], base), type=m.type,
                                       color=color, scale=m.size or 1.0))
    relations = []
    for r in explicit_relations(ws, mentions):
        if which[r.a] == which[r.b]:
            raise PromptError(f"the prompt {bounded(text)} puts {objects[which[r.a]].name} {r.kind} itself; "
                              "name two objects for a relation")
        for a in made[which[r.a]]:  # each of "three apples on a plate" is on it
            for b in made[which[r.b]]:
                relations.append(SceneRelation(kind=r.kind, a=objects[a].name,  # type: ignore[arg-type]
                                               b=objects[b].name))
    return objects, relations


NEGATIONS = frozenset({"no", "not", "without", "except", "never", "nor", "none", "dont", "nothing"})
NUMBERS = {"two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9,
           "ten": 10, "eleven": 11, "twelve": 12}


def _refuse_negated(ws: list[str], m: Mention) -> None:
    """A mention with a negation among the two words before it ("no apple", "without a mug")."""
    start = m.first if m.first >= 0 else m.start
    said = [w for w in ws[max(0, start - 2):start] if w in NEGATIONS or w.endswith("n't")]
    if said:
        raise PromptError(f"the prompt says {' '.join(ws[max(0, start - 2):m.end])!r}: a scene is made of "
                          "what it holds, so name only the objects it should hold")


def _count(ws: list[str], m: Mention) -> int:
    """How many objects the mention asks for: the number word or digits just before it, else one."""
    start = m.first if m.first >= 0 else m.start
    word = ws[start - 1] if start > 0 else ""
    n = int(word) if word.isdigit() else NUMBERS.get(word, 1)
    if n > MAX_OBJECTS:
        raise PromptError(f"the prompt asks for {n} {m.noun}; a scene holds at most {MAX_OBJECTS} objects")
    return max(n, 1)


def _antecedent(ws: list[str], m: Mention, before: list[Mention], which: list[int],
                objects: list[SceneObject]) -> int | None:
    """The object an earlier mention made that the definite ``m`` names again, if exactly one fits."""
    if m.first <= 0 or ws[m.first - 1] != "the" or m.plural:
        return None
    fits = {which[k] for k, e in enumerate(before)
            if e.type == m.type and (not m.colours or objects[which[k]].color in m.colours)}
    return fits.pop() if len(fits) == 1 else None


def best_goal(text: str) -> tuple[Goal, float] | None:
    ranked = OfflinePlanner().match(text)
    if not ranked or ranked[0].score < GOAL_THRESHOLD:
        return None
    goal = next(g for g in GOALS if g.name == ranked[0].label)
    return goal, ranked[0].score


def describe(prompt: str, retrieval: Retrieval | None = None) -> tuple[SceneDescription, Source]:
    """The scene ``prompt`` asks for; ``retrieval`` is the catalog ranked against the prompt."""
    text = check_prompt(prompt)
    objects, relations = _from_mentions(text)
    source = Source("mentions")
    if not relations and len(objects) < LIST_OF_OBJECTS:  # "a mug, a plate and a book" is the scene
        goal = best_goal(text)
        if goal is not None:
            g_objects, g_relations = _from_goal(goal[0])
            have = {o.type for o in g_objects}
            extra = [o for o in objects if o.type not in have]  # named objects the goal lacks join it
            objects, relations, source = g_objects + extra, g_relations, Source(f"goal:{goal[0].name}",
                                                                                round(goal[1], 3))
    if not objects and retrieval is not None and retrieval.found:
        for hit in retrieval.hits[:MAX_RETRIEVED]:
            if hit.score >= MIN_RETRIEVED_SCORE:
                objects.append(SceneObject(name=_unique([o.name for o in objects], hit.type), type=hit.type))
        source = Source("retrieval", retrieval.hits[0].score)
    if not objects:
        raise PromptError(f"the prompt {bounded(text)} names no object of the catalog and matches no goal: "
                          "name objects (`vcage catalog` lists them) or a goal (`vcage tasks`)")
    if len(objects) > MAX_OBJECTS:
        raise PromptError(f"the prompt {bounded(text)} names {len(objects)} objects; a scene holds at most "
                          f"{MAX_OBJECTS} on the table: name fewer")
    relations += pairing(tuple(objects), relations)
    relations += row(tuple(objects), relations)
    data = {"prompt": text, "objects": [o.model_dump() for o in objects],
            "relations": [r.model_dump() for r in relations], "text": image_text(tuple(objects), relations)}
    try:
        return _parse(data), source
    except SceneDescriptionError as exc:
        raise SceneDescriptionError(f"{exc} (built offline from {source.kind}); rephrase the prompt") \
            from None


__all__ = ["SceneDescription", "Source", "describe"]
