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
from vcage.planning.offline import OfflinePlanner
from vcage.synthesis.asked import read_prompt
from vcage.synthesis.description import MAX_OBJECTS, SceneDescription, SceneObject, SceneRelation
from vcage.synthesis.description import parse_description as _parse
from vcage.synthesis.errors import PromptError, SceneDescriptionError
from vcage.synthesis.prompt import check_prompt
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
    """The objects and relations the prompt asks for (:func:`~vcage.synthesis.asked.read_prompt`),
    named; a negated object ("no apple") is refused: the scene is made of what it holds."""
    asked = read_prompt(text)
    if asked.negated:
        raise PromptError(f"the prompt says {asked.negated[0].phrase!r}: a scene is made of what it holds, "
                          "so name only the objects it should hold")
    objects: list[SceneObject] = []
    made: list[range] = []  # group -> its objects ("three apples": all three)
    for g in asked.objects:
        base = f"{g.color}_{g.type}" if g.color else g.type
        start = len(objects)
        for _ in range(g.count):
            objects.append(SceneObject(name=_unique([o.name for o in objects], base), type=g.type,
                                       color=g.color, scale=g.scale))
        made.append(range(start, len(objects)))
    relations = [SceneRelation(kind=r.kind, a=objects[a].name, b=objects[b].name)  # type: ignore[arg-type]
                 for r in asked.relations for a in made[r.a] for b in made[r.b]]  # each of three apples
    return objects, relations


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
