"""The offline planner: no network, deterministic.

Explicit sequences ("put the mouse on the pad, then press the bell") are parsed clause by clause
into subtasks; anything else is matched against the goal library by paraphrase similarity. An
instruction it cannot ground raises :class:`PlanningError` listing what it can do.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from vcage.assets.catalog import CATALOG
from vcage.errors import PlanningError
from vcage.planning.goals import GOALS, Goal, press, put_in, put_on
from vcage.planning.language import Matcher
from vcage.planning.schema import Plan, PlanObject, Subtask

MATCH_THRESHOLD = 0.34  # lowest paraphrase score accepted as a goal

# clause separators of an explicit sequence
_SPLIT = re.compile(r"\s*(?:,\s*(?:and\s+)?then\s+|;\s*|\.\s+|,?\s+and\s+then\s+|,?\s+then\s+"
                    r"|,?\s+after\s+that,?\s+|,\s*and\s+|,\s+)\s*")
_PLACE = re.compile(r"^(?:please\s+)?(?:put|place|move|set|drop|lay|stack|nest|bring|carry)\s+"
                    r"(?P<obj>.+?)\s+(?P<rel>on top of|onto|on|into|inside|in)\s+(?P<target>.+)$")
_PRESS = re.compile(r"^(?:please\s+)?(?:press|push|click|ring|hit|tap|silence|flip|toggle|turn on|turn off|"
                    r"switch on|switch off|use)\s+(?P<obj>.+)$")
SIZES = {"small": 0.85, "little": 0.85, "smaller": 0.85, "large": None, "big": None, "larger": None}
_COLOR_WORDS = frozenset(c for t in CATALOG.values() for c in t.colors)
# spoken names -> catalog types (besides the type names themselves, with spaces)
ALIASES = {
    "pad": "mouse_pad", "mousepad": "mouse_pad", "stand": "object_stand", "display stand": "object_stand",
    "phone stand": "phone_stand", "charging stand": "phone_stand", "mat": "stamp_mat", "ink mat": "stamp_mat",
    "ink pad": "stamp_mat", "stamp": "seal", "clock": "alarm_clock", "alarm": "alarm_clock",
    "light switch": "switch", "cellphone": "phone", "smartphone": "phone", "cube": "block",
    "loaf": "bread", "mobile": "phone", "cell phone": "phone", "service bell": "bell",
}


@dataclass
class _Objects:
    """Objects named so far in a sequence, keyed by (type, colour)."""

    items: dict[tuple[str, str | None, float | None], PlanObject] = field(default_factory=dict)

    def resolve(self, phrase: str, clause: str, fresh: bool = False) -> str:
        """The plan object ``phrase`` names (``fresh``: a new one even if the type was seen)."""
        words = re.sub(r"\b(the|a|an|my|your|its|their|this|that|other|another)\b", " ",
                       phrase.lower()).split()
        color = next((w for w in words if w in _COLOR_WORDS), None)
        size = next((SIZES[w] for w in words if w in SIZES), None)
        noun = " ".join(w for w in words if w != color and w not in SIZES)
        type_ = _type_of(noun)
        if type_ is None:
            raise PlanningError(
                f"unknown object {phrase!r} in {clause!r}; known objects: "
                f"{', '.join(n.replace('_', ' ') for n in CATALOG.names())}")
        if color is not None and color not in CATALOG.get(type_).colors:
            raise PlanningError(f"there is no {color} {type_.replace('_', ' ')}; colours: "
                                f"{', '.join(sorted(CATALOG.get(type_).colors))}")
        key: tuple[str, str | None, float | None] = (type_, color, size)
        if key not in self.items or fresh:
            same = [k for k in self.items if k[0] == type_]
            if same and color is None and size is None and not fresh:
                return self.items[same[0]].name  # "the block" again
            name = f"{color}_{type_}" if color else type_
            if any(o.name == name for o in self.items.values()):
                name = f"{name}{len(same) + 1}"
            key = (type_, color, size if not fresh else -float(len(same) + 1))
            self.items[key] = PlanObject(name=name, type=type_, color=color, scale=size)
        return self.items[key].name


def _type_of(noun: str) -> str | None:
    noun = noun.strip()
    for cand in (noun, noun.rstrip("s"), noun[:-2] if noun.endswith("es") else noun):
        if cand.replace(" ", "_") in CATALOG:
            return cand.replace(" ", "_")
        if cand in ALIASES:
            return ALIASES[cand]
    last = noun.split()[-1] if noun else ""
    return ALIASES.get(last) or (last if last in CATALOG else None)


class OfflinePlanner:
    name = "offline"

    def __init__(self, goals: tuple[Goal, ...] = GOALS, threshold: float = MATCH_THRESHOLD) -> None:
        self.goals = {g.name: g for g in goals}
        self.threshold = threshold
        self.matcher = Matcher((g.name, p) for g in goals for p in (*g.phrasings, g.name.replace("_", " ")))

    def plan(self, instruction: str) -> Plan:
        text = " ".join(instruction.split())
        if not re.search(r"[A-Za-z]{2,}", text):
            raise PlanningError(f"empty or unintelligible instruction {instruction!r}; {self.capabilities()}")
        sequence = self.parse_sequence(text)
        if sequence is not None:
            return sequence
        ranked = self.matcher.score(text)
        if ranked and ranked[0][0] >= self.threshold:
            return self.goals[ranked[0][1]].plan(text)
        near = ", ".join(label for s, label in ranked[:3] if s > 0) or "none"
        raise PlanningError(f"cannot ground {instruction!r} (closest goals: {near}); {self.capabilities()}")

    def parse_sequence(self, text: str) -> Plan | None:
        """A plan if every clause of ``text`` is a command it understands, else None."""
        clauses = [c.strip(" .!") for c in _SPLIT.split(text.lower()) if c and c.strip(" .!")]
        objects = _Objects()
        subtasks: list[Subtask] = []
        for clause in clauses:
            sub = self._clause(clause, objects)
            if sub is None:
                return None
            subtasks.append(sub)
        if not subtasks:
            return None
        order = list(objects.items.values())
        return Plan(instruction=text, objects=tuple(order), subtasks=tuple(subtasks))

    def _clause(self, clause: str, objects: _Objects) -> Subtask | None:
        m = _PLACE.match(clause)
        if m:
            obj = objects.resolve(m["obj"], clause)
            target = objects.resolve(m["target"], clause)
            if target == obj:  # "put the bowl in the other bowl"
                target = objects.resolve(m["target"], clause, fresh=True)
            o, t = (_find(objects, obj), _find(objects, target))
            if t.type == "object_stand" and o.type == "phone":
                return None
            word = "in" if m["rel"] in ("in", "into", "inside") else "on"
            text = f"the {_words(o)} is {word} the {_words(t)}"
            kind = CATALOG.get(t.type).placements[0].kind if CATALOG.get(t.type).placements else None
            if kind is None:
                raise PlanningError(f"nothing can be put on or in the {t.type.replace('_', ' ')} "
                                    f"(in {clause!r}); objects that hold others: "
                                    f"{', '.join(x.name for x in CATALOG.values() if x.placements)}")
            return (put_in if kind == "in" else put_on)(obj, target, text)
        m = _PRESS.match(clause)
        if m:
            obj = objects.resolve(m["obj"], clause)
            o = _find(objects, obj)
            fps = CATALOG.get(o.type).functional_points
            if not fps or fps[0].joint is None:
                raise PlanningError(f"a {o.type.replace('_', ' ')} cannot be pressed (in {clause!r}); "
                                    f"pressable: {', '.join(x.name for x in CATALOG.by_tag('pressable'))}")
            point = fps[0].name if o.type == "switch" else None
            return press(obj, f"the {_words(o)} is pressed", point=point)
        return None

    def capabilities(self) -> str:
        goals = "; ".join(f"{g.phrasings[0]}" for g in self.goals.values())
        return (f"the offline planner knows these goals: {goals}; and explicit sequences such as "
                "'put the mouse on the mouse pad, then press the bell'. For anything else use an "
                "LLM planner (--planner llm with VCAGE_LLM_BASE_URL and VCAGE_LLM_MODEL set)")


def _find(objects: _Objects, name: str) -> PlanObject:
    return next(o for o in objects.items.values() if o.name == name)


def _words(o: PlanObject) -> str:
    return f"{o.color + ' ' if o.color else ''}{o.type.replace('_', ' ')}"
