"""The ``Plan``: what an instruction grounds to, validated the same way for every planner.

A plan names the objects of the scene (catalog types, optionally standing on another object),
relations for their initial layout, and an ordered list of subtasks. Each subtask is one skill
call with arguments, a short description (what a critic is asked about) and the ground-truth
predicates that define its success (what the oracle checks). A plan matched to a library goal says
how confidently (``match``); that field is optional and left out of dumps when absent, so plans
written before it existed, and plans without a goal, read and dump as before.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    SerializerFunctionWrapHandler,
    field_validator,
    model_serializer,
    model_validator,
)

from vcage.assets.catalog import CATALOG
from vcage.vocabulary import PLAN_SKILLS, PREDICATES


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PlanObject(_Strict):
    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_]+$")
    type: str
    color: str | None = None
    scale: float | None = Field(default=None, ge=0.5, le=1.5)  # None: drawn from the type's range
    on: str | None = None  # name of the object it starts on or in (None: the table)

    @field_validator("type")
    @classmethod
    def _known_type(cls, v: str) -> str:
        if v not in CATALOG:
            raise ValueError(f"unknown object type {v!r}; catalog types: {', '.join(CATALOG.names())}")
        return v

    @model_validator(mode="after")
    def _known_color(self) -> PlanObject:
        if self.color is not None and self.color not in CATALOG.get(self.type).colors:
            raise ValueError(f"{self.type} has no colour {self.color!r}; "
                             f"variants: {sorted(CATALOG.get(self.type).colors)}")
        return self


class PlanRelation(_Strict):
    kind: Literal["left_of", "right_of", "near", "far_from"]
    a: str
    b: str
    distance: float = Field(default=0.05, ge=0.0, le=1.0)


class Predicate(_Strict):
    name: str
    args: tuple[str, ...]

    @model_validator(mode="after")
    def _arity(self) -> Predicate:
        if self.name not in PREDICATES:
            raise ValueError(f"unknown predicate {self.name!r}; valid: {', '.join(PREDICATES)}")
        PREDICATES.get(self.name).check_arity(self.args)
        return self

    def __str__(self) -> str:
        return f"{self.name}({', '.join(self.args)})"


class Subtask(_Strict):
    skill: str
    args: dict[str, Any] = Field(default_factory=dict)
    description: str = Field(min_length=3)
    predicates: tuple[Predicate, ...] = ()

    @model_validator(mode="after")
    def _skill_signature(self) -> Subtask:
        if self.skill not in PLAN_SKILLS:
            raise ValueError(f"unknown skill {self.skill!r}; valid: {', '.join(PLAN_SKILLS)}")
        PLAN_SKILLS.get(self.skill).check_args(self.args)
        return self

    def objects(self) -> list[str]:
        named = PLAN_SKILLS.get(self.skill).object_args(self.args)
        return named + [a for p in self.predicates for a in p.args]


class GoalMatch(_Strict):
    """How an instruction matched its library goal: the confidence (0..1), the threshold it had to
    reach, and the runners-up with theirs."""

    score: float = Field(ge=0.0, le=1.0)
    threshold: float = Field(ge=0.0, le=1.0)
    alternatives: tuple[tuple[str, float], ...] = ()

    def __str__(self) -> str:
        alts = ", ".join(f"{g} {s:.2f}" for g, s in self.alternatives)
        return f"match {self.score:.2f} >= {self.threshold:.2f}" + (f"; next: {alts}" if alts else "")


class Plan(_Strict):
    instruction: str = Field(min_length=1)
    goal: str | None = None  # the library goal it was matched to, if any
    objects: tuple[PlanObject, ...] = Field(min_length=1)
    relations: tuple[PlanRelation, ...] = ()
    subtasks: tuple[Subtask, ...] = Field(min_length=1)
    match: GoalMatch | None = None  # how confidently ``goal`` was matched (None: not matched)

    @model_serializer(mode="wrap")
    def _without_empty_match(self, handler: SerializerFunctionWrapHandler) -> Any:
        data = handler(self)
        if isinstance(data, dict) and data.get("match", 0) is None:
            del data["match"]  # plans without a goal match dump exactly as before the field existed
        return data

    @model_validator(mode="after")
    def _references(self) -> Plan:
        names = [o.name for o in self.objects]
        if len(set(names)) != len(names):
            raise ValueError(f"object names must be unique: {names}")
        known = set(names)
        for o in self.objects:
            if o.on is not None and o.on not in known:
                raise ValueError(f"object {o.name!r} starts on unknown object {o.on!r}")
        for r in self.relations:
            for n in (r.a, r.b):
                if n not in known:
                    raise ValueError(f"relation {r.kind}({r.a}, {r.b}) names unknown object {n!r}")
        for i, st in enumerate(self.subtasks):
            unknown = [n for n in st.objects() if n not in known]
            if unknown:
                raise ValueError(f"subtask {i} ({st.skill}) names unknown object(s) {unknown}; "
                                 f"plan objects: {names}")
            target, place = st.args.get("target"), st.args.get("placement")
            if isinstance(target, str) and place is not None:
                valid = [p.name for p in CATALOG.get(self.object(target).type).placements]
                if place not in valid:
                    raise ValueError(f"subtask {i} ({st.skill}) names placement {place!r} of {target!r}; "
                                     f"its placements: {valid}")
        self._drawers_open_when_used()
        self._faces_exist()
        self._loops_and_hooks_exist()
        return self

    def _loops_and_hooks_exist(self) -> None:
        """Only an object with a loop (a mug's handle) is hung, and only on one with a hook (a rack's
        peg): elsewhere ``hanging`` could never hold."""
        types = {o.name: o.type for o in self.objects}
        for i, st in enumerate(self.subtasks):
            pairs: list[tuple[object, object]] = [(st.args.get("obj"), st.args.get("target"))] \
                if st.skill == "hang" else []
            pairs += [(p.args[0], p.args[1]) for p in st.predicates
                      if p.name == "hanging" and len(p.args) == 2]
            for obj, host in pairs:
                for name, kind in ((obj, "loop"), (host, "hook")):
                    if not isinstance(name, str) or name not in types \
                            or CATALOG.get(types[name]).point_of_kind(kind) is not None:
                        continue
                    having = CATALOG.with_point(kind)
                    raise ValueError(f"subtask {i} ({st.skill}) hangs {obj!r} on {host!r}, but {name!r}, "
                                     f"a {types[name]}, has no {kind}; objects with one: {having}")

    def _faces_exist(self) -> None:
        """Only an object with a face (a board's code, a fan's outlet) is turned to face the robot or
        checked for it: on another, ``facing`` could never hold."""
        types = {o.name: o.type for o in self.objects}
        for i, st in enumerate(self.subtasks):
            named = [st.args.get("obj")] if st.skill == "turn_to_face" else []
            named += [p.args[0] for p in st.predicates if p.name == "facing" and p.args]
            for obj in named:
                if isinstance(obj, str) and obj in types and CATALOG.get(types[obj]).face is None:
                    faced = CATALOG.names_where(lambda t: t.face is not None)
                    raise ValueError(f"subtask {i} ({st.skill}) turns {obj!r}, a {types[obj]}, to face the "
                                     f"robot, but it has no face to turn; objects with one: {faced}")

    def _drawers_open_when_used(self) -> None:
        """Drawers are opened and closed on objects that have one, and something put into a drawer goes
        in while it is open: every drawer starts shut, an ``open_drawer`` subtask opens it,
        ``close_drawer`` shuts it."""
        types = {o.name: o.type for o in self.objects}
        opened: set[str] = set()
        for i, st in enumerate(self.subtasks):
            target = st.args.get("target")
            obj = st.args.get("obj")
            if st.skill in ("open_drawer", "close_drawer") and isinstance(obj, str) and obj in types \
                    and not CATALOG.get(types[obj]).drawer_handles:
                raise ValueError(f"subtask {i} ({st.skill}) names {obj!r}, a {types[obj]}, which has no "
                                 "drawer")
            if st.skill == "open_drawer":
                opened.add(str(st.args["obj"]))
            elif st.skill == "close_drawer":
                opened.discard(str(st.args["obj"]))
            elif st.skill == "pick_and_place" and isinstance(target, str) and target in types \
                    and target not in opened and _in_a_drawer(types[target], st.args.get("placement")):
                raise ValueError(f"subtask {i} puts {st.args['obj']!r} into the drawer of {target!r} "
                                 f"while it is shut; open it first (an open_drawer subtask of {target!r} "
                                 "before it)")

    def object(self, name: str) -> PlanObject:
        return next(o for o in self.objects if o.name == name)

    def summary(self) -> str:
        goal = f"  (goal: {self.goal}{', ' + str(self.match) if self.match else ''})" if self.goal else ""
        lines = [f"instruction: {self.instruction}{goal}"]
        lines.append("objects: " + ", ".join(
            f"{o.name} ({(o.color + ' ') if o.color else ''}{o.type}{', on ' + o.on if o.on else ''})"
            for o in self.objects))
        for i, st in enumerate(self.subtasks, 1):
            args = ", ".join(f"{k}={v}" for k, v in st.args.items())
            preds = ", ".join(str(p) for p in st.predicates)
            lines.append(f"{i}. {st.skill}({args}): {st.description}  [{preds}]")
        return "\n".join(lines)


def _in_a_drawer(type_name: str, placement: str | None) -> bool:
    """Whether placement ``placement`` (None: the first) of ``type_name`` is a drawer's inside."""
    places = CATALOG.get(type_name).placements
    return bool(places) and CATALOG.get(type_name).placement(placement).joint is not None


def plan_json_schema() -> dict[str, Any]:
    """The JSON schema an LLM planner is asked to follow (without ``match``, which the planner that
    matched a goal fills in, never a model)."""
    schema = Plan.model_json_schema()
    schema["properties"].pop("match", None)
    schema.get("$defs", {}).pop("GoalMatch", None)
    return schema
