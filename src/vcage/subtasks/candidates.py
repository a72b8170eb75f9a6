"""Candidate subtasks of a scene, enumerated from the catalog's annotations.

The actionable relations of a scene are the pairs (graspable object, object with a placement
surface or container) and the functional points that move a joint (buttons, levers, switches:
press or turn). Each becomes a candidate subtask with its success predicates in the vocabulary:

- ``put_on`` / ``put_in``: ``pick_and_place(obj, target)`` with ``on``/``inside(obj, target)`` and
  ``released(obj)``, for a target's first placement (the one the predicates check), when the object
  could fit: through the container's opening (``in``; an object of the container's own type only
  when the type nests, a bowl in a larger bowl) or onto the surface (``on``: no wider than the
  target is long, and at most :data:`ON_AREA` times its footprint);
- ``press``: ``press(obj, point)`` with ``pressed(obj)`` and ``upright(obj)``, per point with a joint.

Offline, the candidate's code *is data*: the skill call as canonical JSON (``source="template"``).
A model may write the code instead (:mod:`vcage.subtasks.codegen`, ``source="llm"``); the candidate's
identity then includes the program's hash.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field, replace
from typing import Any

from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.objects.containers import NEST_RATIO, NESTING
from vcage.planning.schema import Predicate, Subtask
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.records import LLM, TEMPLATE

FIT_SLACK = 0.01  # metres an object may exceed a container's opening or a surface's length
ON_AREA = 1.2  # an object put on another covers at most this many times its footprint


def _digest(data: Any) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


@dataclass(frozen=True)
class Candidate:
    """One candidate subtask of one scene: the intended skill call, its description and predicates,
    and the code that carries it out (template JSON or a generated program)."""

    scene_id: str
    template: str  # put_on | put_in | press
    skill: str
    args: dict[str, Any]
    description: str
    predicates: tuple[Predicate, ...]
    code: str = ""
    source: str = TEMPLATE
    model: str | None = None
    prompt_hash: str | None = None
    objects: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        if not self.code:
            object.__setattr__(self, "code", json.dumps([{"skill": self.skill, "args": self.args}],
                                                        sort_keys=True))

    @property
    def code_hash(self) -> str:
        return hashlib.sha256(self.code.encode()).hexdigest()

    @property
    def id(self) -> str:
        """Stable identity: scene, skill call and code; trial seeds are derived from it."""
        return _digest({"scene": self.scene_id, "skill": self.skill, "args": self.args,
                        "code": self.code_hash})[:16]

    @property
    def is_program(self) -> bool:
        return self.source == LLM

    def subtask(self) -> Subtask:
        """The subtask as a plan states it (what the critic is told)."""
        return Subtask(skill=self.skill, args=self.args, description=self.description,
                       predicates=self.predicates)

    def with_program(self, code: str, model: str, prompt_hash: str) -> Candidate:
        return replace(self, code=code, source=LLM, model=model, prompt_hash=prompt_hash)

    def program_text(self) -> str:
        """The template as a program of the skill API (what a model is taught to write)."""
        args = ", ".join(f"{k}={v!r}" for k, v in self.args.items())
        return f"{self.skill}({args})\n"


def _words(obj: ObjectSpec) -> str:
    return obj.type.replace("_", " ")


def _fits(a: ObjectSpec, ta: ObjectType, b: ObjectSpec, tb: ObjectType, kind: str) -> bool:
    ax = sorted((ta.size[0] * a.scale, ta.size[1] * a.scale))
    bx = sorted((tb.size[0] * b.scale, tb.size[1] * b.scale))
    if kind == "in" and a.type == b.type:  # nesting: only flared containers, the inner one smaller
        return a.type in NESTING and a.scale <= NEST_RATIO * b.scale + 1e-9
    if kind == "in":  # through the opening, narrow side to narrow side
        return ax[0] <= bx[0] + FIT_SLACK and ax[1] <= bx[1] + FIT_SLACK
    # onto the surface: no wider than it is long, and not much larger (a pot does not go on a plate)
    return ax[0] <= bx[1] + FIT_SLACK and ax[0] * ax[1] <= ON_AREA * bx[0] * bx[1]


def candidates(scene_id: str, spec: SceneSpec) -> list[Candidate]:
    """Every candidate subtask of ``spec``, in a fixed order (object order of the spec)."""
    types = {o.name: CATALOG.get(o.type) for o in spec.objects}
    out: list[Candidate] = []
    for a in spec.objects:
        ta = types[a.name]
        if not ta.grasps or ta.fixed:
            continue
        for b in spec.objects:
            tb = types[b.name]
            if b.name == a.name or not tb.placements:
                continue
            place = tb.placements[0]
            if not _fits(a, ta, b, tb, place.kind):
                continue
            rel, template = ("inside", "put_in") if place.kind == "in" else ("on", "put_on")
            prep = "in" if rel == "inside" else "on"
            out.append(Candidate(scene_id, template, "pick_and_place", {"obj": a.name, "target": b.name},
                                 f"put the {_words(a)} {prep} the {_words(b)}",
                                 (Predicate(name=rel, args=(a.name, b.name)),
                                  Predicate(name="released", args=(a.name,))), objects=(a.name, b.name)))
    for x in spec.objects:
        for point in types[x.name].functional_points:
            if point.joint is None:
                continue
            verb = "turn" if point.kind == "switch" else "press"
            out.append(Candidate(scene_id, "press", "press", {"obj": x.name, "point": point.name},
                                 f"{verb} the {_words(x)} ({point.name})",
                                 (Predicate(name="pressed", args=(x.name,)),
                                  Predicate(name="upright", args=(x.name,))), objects=(x.name,)))
    return out
