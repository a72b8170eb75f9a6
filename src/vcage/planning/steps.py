"""Explicit steps: one clause to one subtask, and the plan objects a sequence of steps names.

``_Objects`` gives each object phrase of a sequence its plan object (the same object when a later
step names it again, a new one for "the other ..."); ``_clause`` reads one clause as a subtask of a
verified skill, checking that the catalog object can do what the step asks (be put on or in, have a
drawer, hang, face the robot, be pressed).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vcage.assets.catalog import CATALOG
from vcage.errors import PlanningError
from vcage.planning.clauses import _DRAWER, _FACE, _HANG, _PLACE, _PRESS
from vcage.planning.goals import close_drawer, hang, open_drawer, press, put_in, put_on, turn_to_face
from vcage.planning.language import bounded
from vcage.planning.lexicon import ObjectRef, listed, parse_phrase
from vcage.planning.schema import PlanObject, Subtask


@dataclass
class _Objects:
    """The plan objects named so far in a sequence."""

    items: list[tuple[ObjectRef, PlanObject]] = field(default_factory=list)

    def resolve(self, ref: ObjectRef, type_: str, clause: str, fresh: bool = False) -> PlanObject:
        """The plan object ``ref`` names: one already named if it is the same, else a new one
        (``fresh`` or "the other ...": always a new one)."""
        same_type = [o for _, o in self.items if o.type == type_]
        if not (fresh or ref.other):
            exact = [o for r, o in self.items if o.type == type_ and o.color == ref.colour
                     and (not ref.sized or r.size == ref.size)]
            if ref.colour is None and not ref.sized and same_type:
                exact = same_type  # "the block" again
            if len(exact) == 1:
                return exact[0]
            if len(exact) > 1:
                raise PlanningError(
                    f"{bounded(ref.text, 80)} in {bounded(clause, 120)} could be any of "
                    f"{listed([_words(o) for o in exact])}; name it by its colour")
        name = f"{ref.colour}_{type_}" if ref.colour else type_
        if any(o.name == name for _, o in self.items):
            name = f"{name}{len(same_type) + 1}"
        obj = PlanObject(name=name, type=type_, color=ref.colour, scale=ref.size)
        self.items.append((ref, obj))
        return obj

    def objects(self) -> tuple[PlanObject, ...]:
        return tuple(o for _, o in self.items)


def _words(o: PlanObject) -> str:
    return f"{o.color + ' ' if o.color else ''}{o.type.replace('_', ' ')}"


def _type_in_context(ref: ObjectRef, other: str | None) -> str:
    """The type ``ref`` names next to an object of type ``other`` (a phone's stand: the phone stand)."""
    if "phone_stand" in ref.accepts and other == "phone":
        return "phone_stand"
    return ref.type


def _check_colour(ref: ObjectRef, type_: str) -> None:
    if ref.colour is not None and ref.colour not in CATALOG.get(type_).colors:
        raise PlanningError(f"there is no {ref.colour} {type_.replace('_', ' ')}; colours: "
                            f"{', '.join(sorted(CATALOG.get(type_).colors))}")


def _clause(clause: str, objects: _Objects) -> Subtask:
    m = _PLACE.match(clause)
    if m:
        o_ref, t_ref = parse_phrase(m["obj"], clause), parse_phrase(m["target"], clause)
        o_type = _type_in_context(o_ref, None)
        t_type = _type_in_context(t_ref, o_type)
        _check_colour(o_ref, o_type)
        _check_colour(t_ref, t_type)
        o = objects.resolve(o_ref, o_type, clause)
        t = objects.resolve(t_ref, t_type, clause)
        if t.name == o.name:  # "put the bowl in the other bowl"
            t = objects.resolve(t_ref, t_type, clause, fresh=True)
        places = CATALOG.get(t.type).placements
        if not places:
            raise PlanningError(f"nothing can be put on or in the {t.type.replace('_', ' ')} "
                                f"(in {bounded(clause)}); objects that hold others: "
                                f"{', '.join(CATALOG.names_where(lambda t: t.placements))}")
        kind = places[0].kind
        text = f"the {_words(o)} is {'in' if kind == 'in' else 'on'} the {_words(t)}"
        return (put_in if kind == "in" else put_on)(o.name, t.name, text)
    m = _DRAWER.match(clause)
    if m:
        ref = parse_phrase(m["obj"], clause)
        _check_colour(ref, ref.type)
        o = objects.resolve(ref, ref.type, clause)
        if not CATALOG.get(o.type).drawer_handles:
            with_drawers = CATALOG.names_where(lambda t: t.drawer_handles)
            raise PlanningError(f"a {o.type.replace('_', ' ')} has no drawer to open or close (in "
                                f"{bounded(clause)}); objects with a drawer: {', '.join(with_drawers)}")
        if m["verb"] in ("close", "shut"):
            return close_drawer(o.name, f"the {_words(o)}'s drawer is shut")
        return open_drawer(o.name, f"the {_words(o)}'s drawer is pulled open")
    m = _HANG.match(clause)
    if m:
        o_ref, t_ref = parse_phrase(m["obj"], clause), parse_phrase(m["target"], clause)
        _check_colour(o_ref, o_ref.type)
        _check_colour(t_ref, t_ref.type)
        o, t = objects.resolve(o_ref, o_ref.type, clause), objects.resolve(t_ref, t_ref.type, clause)
        for x, kind, what in ((o, "loop", "hung up"), (t, "hook", "hung from")):
            if CATALOG.get(x.type).point_of_kind(kind) is None:
                having = CATALOG.with_point(kind)
                raise PlanningError(f"a {x.type.replace('_', ' ')} has no {kind} to be {what} (in "
                                    f"{bounded(clause)}); objects with one: {', '.join(having)}")
        return hang(o.name, t.name, f"the {_words(o)} hangs on the {_words(t)}")
    m = _FACE.match(clause)
    if m:
        ref = parse_phrase(m["obj"], clause)
        _check_colour(ref, ref.type)
        o = objects.resolve(ref, ref.type, clause)
        if CATALOG.get(o.type).face is None:
            faced = CATALOG.names_where(lambda t: t.face is not None)
            raise PlanningError(f"a {o.type.replace('_', ' ')} has no face to turn towards the robot (in "
                                f"{bounded(clause)}); objects with one: {', '.join(faced)}")
        return turn_to_face(o.name, f"the {_words(o)} is turned to face the robot, standing on the table")
    m = _PRESS.match(clause)
    if m:
        ref = parse_phrase(m["obj"], clause)
        _check_colour(ref, ref.type)
        o = objects.resolve(ref, ref.type, clause)
        fps = CATALOG.get(o.type).functional_points
        if CATALOG.get(o.type).drawer_handles:
            raise PlanningError(f"a {o.type.replace('_', ' ')}'s handle opens or closes its drawer, it "
                                f"is not pressed (in {bounded(clause)}); say 'open the {_words(o)}' or "
                                f"'close the {_words(o)}'")
        if not fps or fps[0].joint is None:
            raise PlanningError(f"a {o.type.replace('_', ' ')} cannot be pressed (in {bounded(clause)}); "
                                f"pressable: {', '.join(x.name for x in CATALOG.by_tag('pressable'))}")
        point = None
        if o.type == "switch":
            if m["verb"] in ("turn off", "switch off"):
                raise PlanningError(f"the switch starts in its off position, so it cannot be turned "
                                    f"off (in {bounded(clause)}); say 'turn on the switch' or "
                                    "'flip the switch'")
            point = fps[0].name
        return press(o.name, f"the {_words(o)} is pressed", point=point)
    raise PlanningError(f"cannot read {bounded(clause)} as a step: a step is 'put/place/move X on/in Y', "
                        "'press/ring/flip Z', 'open/close the drawer', 'hang X on Y' or 'turn X to face "
                        "me', naming catalog objects")
