"""The offline scene describer: a prompt to a :class:`SceneDescription` without any model.

Objects come, in this order of preference, from the catalog objects the prompt names (with the
relations it states between them, "the apple in the bowl"), from the best-matching goal of the
planner's library (its objects; its subtasks' ``on`` / ``inside`` goals become relations), or from
retrieval over the catalog. :mod:`vcage.synthesis.templates` arranges what the prompt leaves free.
"""

from __future__ import annotations

from dataclasses import dataclass

from vcage.planning.goals import GOALS, Goal
from vcage.planning.language import bounded
from vcage.planning.offline import OfflinePlanner
from vcage.synthesis.description import MAX_OBJECTS, SceneDescription, SceneObject, SceneRelation
from vcage.synthesis.description import parse_description as _parse
from vcage.synthesis.errors import PromptError, SceneDescriptionError
from vcage.synthesis.prompt import check_prompt, explicit_relations, lexicon_mentions
from vcage.synthesis.retrieval import Retrieval
from vcage.synthesis.templates import image_text, pairing, row

GOAL_THRESHOLD = 0.25  # a goal this similar to the prompt lends its objects and relations
MAX_RETRIEVED = 4  # objects a scene takes from retrieval alone
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
    ws, mentions = lexicon_mentions(text)
    objects: list[SceneObject] = []
    for m in mentions:
        color = m.colours[0] if len(m.colours) == 1 else None
        base = f"{color}_{m.type}" if color else m.type
        objects.append(SceneObject(name=_unique([o.name for o in objects], base), type=m.type, color=color,
                                   scale=m.size or 1.0))
    relations = [SceneRelation(kind=r.kind, a=objects[r.a].name, b=objects[r.b].name)  # type: ignore[arg-type]
                 for r in explicit_relations(ws, mentions)]
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
    if not relations:
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
    objects = objects[:MAX_OBJECTS]
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
