"""The offline planner: no network, deterministic, and it never labels a plan with an instruction
the plan does not carry out.

An instruction is read in this order:

1. Explicit steps first ("put the mouse on the pad, then press the bell"; clauses joined by
   "then", "and then", "after that", ";", sentences, commas or "and" before a verb). If any clause is
   a step, the instruction is explicit: every clause must parse, into one subtask each, or it is
   refused with what was understood. A library goal is then considered only if the sentence *is*
   one of the goal's phrasings (confidence >= ``EXACT_MATCH``, e.g. "put the fruit on display");
   a fuzzy match never overrides or completes an explicit instruction.
2. Otherwise the library goal whose phrasings match best, if its confidence reaches the threshold,
   no other goal explains the same words, the sentence has no word of another goal's name that this
   goal's phrasings lack ("make breakfast and serve tea"), names nothing the planner does not know
   ("the laptop"), gives no count ("build two towers"), and the goal's plan contains every catalog
   object the sentence names (a colour the sentence gives is set on the goal's object of that type).

Every plan has at most ``max_subtasks`` subtasks. A :class:`PlanningError` says what was understood
(the objects recognised, what the plan would miss), what the planner can do, and quotes at most
``QUOTE_LIMIT`` characters of the instruction.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from pydantic import ValidationError

from vcage.assets.catalog import CATALOG
from vcage.errors import ConfigError, PlanningError
from vcage.planning.config import MAX_SUBTASKS
from vcage.planning.goals import (
    GOALS,
    Goal,
    close_drawer,
    hang,
    open_drawer,
    press,
    put_in,
    put_on,
    turn_to_face,
)
from vcage.planning.language import Matcher, Scored, bounded, tokens
from vcage.planning.lexicon import (
    ALIASES,
    COLOURS,
    NOUN_WORDS,
    PREPOSITIONS,
    SIZES,
    Mention,
    ObjectRef,
    determiner_phrases,
    find_mentions,
    listed,
    parse_phrase,
    uncovered,
    words,
)
from vcage.planning.schema import GoalMatch, Plan, PlanObject, Subtask

MATCH_THRESHOLD = 0.34  # lowest paraphrase score accepted as a goal
# a sentence that reads as explicit steps but does not parse may still *be* a goal's phrasing
EXACT_MATCH = 0.9

# separators that always end a step; weak ones (commas, "and") only before a verb or an elided step
_STRONG = re.compile(r"\s*(?:;|[.!?](?:\s+|$)|,?\s*\b(?:and\s+)?then\b,?|,?\s*\b(?:and\s+)?after\s+that\b,?"
                     r"|,?\s*\bafterwards\b,?)\s*")
_WEAK = re.compile(r"(\s*,\s*(?:and\s+)?|\s+and\s+)")
_PREFIX = re.compile(r"^(?:(?:please|kindly|now|first|firstly|next|finally|lastly|also|and|robot)\b,?\s*"
                     r"|(?:can|could|would|will)\s+you\s+(?:please\s+)?"
                     r"|i\s+(?:want|need|would\s+like|'?d\s+like)\s+you\s+to\s+)+")
_PLACE_VERBS = "put|place|move|set|drop|lay|stack|nest|bring|carry"
_PRESS_VERBS = "press|push|click|ring|hit|tap|silence|flip|toggle|turn on|turn off|switch on|switch off|use"
_DRAWER_VERBS = "open|pull open|pull out|close|shut"
_REL = r"on top of|onto|on|into|inside of|inside|in"
_PLACE = re.compile(rf"^(?:{_PLACE_VERBS})\s+(?P<obj>.+?)\s+(?P<rel>{_REL})\s+(?P<target>.+)$")
_ELIDED = re.compile(rf"^(?P<obj>.+?)\s+(?P<rel>{_REL})\s+(?P<target>.+)$")  # "..., the cup on the coaster"
_PRESS = re.compile(rf"^(?P<verb>{_PRESS_VERBS})\s+(?P<obj>.+)$")
# "close up the office" and "shut down the laptop" are not about a drawer
_DRAWER = re.compile(rf"^(?P<verb>{_DRAWER_VERBS})\s+(?!(?:up|down|off)\b)(?P<obj>.+)$")
# "turn the QR code board to face me": a step of its own, read before the press verbs ("turn on ...")
_FACE = re.compile(r"^(?:turn|rotate)\s+(?P<obj>.+?)\s+(?:a?round\s+)?(?:to\s+face|towards?)\s+"
                   r"(?:me|us|the\s+robot)$")
_HANG = re.compile(r"^hang\s+(?P<obj>.+?)\s+(?:up\s+)?(?:on|onto|from)\s+(?P<target>.+)$")
_COMMAND = re.compile(rf"^(?:{_PLACE_VERBS}|{_PRESS_VERBS}|{_DRAWER_VERBS}|switch|turn|rotate|hang)\b")
_GERUNDS = {"putting": "put", "placing": "place", "moving": "move", "setting": "set", "dropping": "drop",
            "laying": "lay", "stacking": "stack", "nesting": "nest", "pressing": "press", "pushing": "push",
            "ringing": "ring", "hitting": "hit", "tapping": "tap", "silencing": "silence", "flipping": "flip"}
_ORDER = re.compile(r"^(?P<a>.+?)\s+(?P<when>after|before)\s+(?P<g>[a-z]+ing)\s+(?P<rest>.+)$")
_NEGATION = re.compile(r"\b(?:not|never|without|except|nor|dont|instead)\b|n't\b")
# a goal does its fixed number of things: a count in a goal sentence asks for something else
_COUNT = re.compile(r"\b(?:\d+|two|three|four|five|six|seven|eight|nine|ten|twice|thrice|times|dozen"
                    r"|several|many)\b")


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


def _strip(clause: str) -> str:
    clause = _PREFIX.sub("", clause.strip(" ,.!?")).strip(" ,.!?")
    return re.sub(r"\s*,?\s*please$", "", clause)


def split_clauses(text: str) -> list[str]:
    """The clauses of ``text``, lower-cased, in execution order."""
    clauses: list[str] = []
    for part in _STRONG.split(text.lower()):
        part = _strip(part)
        if not part:
            continue
        pieces = _WEAK.split(part)  # piece, separator, piece, ...
        first = _strip(pieces[0])
        merged = [_elided(first, clauses[-1]) if clauses else first]
        for sep, raw in zip(pieces[1::2], pieces[2::2], strict=True):
            piece = _strip(raw)
            if _COMMAND.match(piece) and merged[-1]:
                merged.append(piece)
            elif _elided(piece, merged[-1]) != piece:
                merged.append(_elided(piece, merged[-1]))
            else:
                merged[-1] = f"{merged[-1]}{sep}{raw}"  # a list inside one step: "the red and blue block"
        for clause in filter(None, merged):
            m = _ORDER.match(clause)
            if m and m["g"] in _GERUNDS:  # "press the bell after putting the cup on the coaster"
                later = f"{_GERUNDS[m['g']]} {m['rest']}"
                clauses += [later, m["a"]] if m["when"] == "after" else [m["a"], later]
            else:
                clauses.append(clause)
    return clauses


def _elided(piece: str, previous: str) -> str:
    """``piece`` with the verb of ``previous`` if it is a placing step without its verb
    ("put the remote in the box and the marker in the cup")."""
    m = _ELIDED.match(piece)
    if (m and not _COMMAND.match(piece) and _PLACE.match(previous)
            and find_mentions(words(m["obj"]), all_objects=True)):
        return f"{previous.split(' ', 1)[0]} {piece}"
    return piece


def _is_step(clause: str) -> bool:
    """Whether ``clause`` is (or tries to be) an explicit step: a step's shape, or a command verb
    (opening or closing a drawer among them: "shut everything down" is not a step) and a catalog
    object."""
    if _PLACE.match(clause) or _PRESS.match(clause):
        return True
    return bool(_COMMAND.match(clause) and find_mentions(words(clause)))


class OfflinePlanner:
    name = "offline"

    def __init__(self, goals: tuple[Goal, ...] = GOALS, threshold: float = MATCH_THRESHOLD,
                 max_subtasks: int = MAX_SUBTASKS) -> None:
        if max_subtasks < 1:
            raise ConfigError(f"max_subtasks must be >= 1 (the most subtasks a plan may have), "
                              f"got {max_subtasks}")
        self.goals = {g.name: g for g in goals}
        self.threshold = threshold
        self.max_subtasks = max_subtasks
        self.matcher = Matcher((g.name, p) for g in goals for p in (*g.phrasings, g.name.replace("_", " ")))
        self._known_words = self.matcher.vocabulary | NOUN_WORDS | COLOURS | frozenset(SIZES)
        # the words that say what a goal is (its name's): another goal's in a sentence asks for more
        self._name_words = {g.name: frozenset(tokens(g.name.replace("_", " "))) for g in goals}

    # -- the one entry point ---------------------------------------------------------------------

    def plan(self, instruction: str) -> Plan:
        text = " ".join(instruction.split())
        if not re.search(r"[A-Za-z]{2,}", text):
            raise PlanningError(f"empty or unintelligible instruction {bounded(instruction)}; "
                                f"{self.capabilities()}")
        if _NEGATION.search(text.lower()):
            raise PlanningError(
                f"cannot ground {bounded(text)}: it says what not to do ('not', 'without', ...), which "
                f"a plan cannot check; say only what the robot should do. {self.capabilities()}")
        clauses = split_clauses(text)
        steps = [c for c in clauses if _is_step(c)]
        if steps:
            return self._explicit(text, clauses, steps)
        return self._goal(text, exact=False)

    # -- explicit steps ----------------------------------------------------------------------------

    def _explicit(self, text: str, clauses: list[str], steps: list[str]) -> Plan:
        if len(steps) > self.max_subtasks:
            raise self._too_long(text, len(steps), "steps")
        others = [c for c in clauses if c not in steps]
        if others:
            raise PlanningError(
                f"cannot ground {bounded(text, 80)}: it mixes explicit steps ({bounded(steps[0], 60)}"
                f"{f' and {len(steps) - 1} more' if len(steps) > 1 else ''}) with {bounded(others[0], 60)}, "
                "which is not a step "
                "('put X on/in Y', 'press Z'); a library goal cannot be combined with explicit steps: give "
                f"either the goal or every step. {self.capabilities()}")
        try:
            return self.parse_sequence(text, clauses)
        except PlanningError as exc:
            try:  # the sentence may be a goal's own phrasing ("put the fruit on display")
                return self._goal(text, exact=True)
            except PlanningError:
                raise exc from None

    def parse_sequence(self, text: str, clauses: list[str] | None = None) -> Plan:
        """The plan of explicit steps ``text`` (one subtask per clause), or :class:`PlanningError`."""
        clauses = split_clauses(text) if clauses is None else clauses
        objects = _Objects()
        subtasks: list[Subtask] = []
        for clause in clauses:
            try:
                subtasks.append(self._clause(clause, objects))
            except PlanningError as exc:
                raise PlanningError(f"{exc}{self._understood(clauses, subtasks)}") from None
        if not subtasks:
            raise PlanningError(f"no step in {bounded(text)}; {self.capabilities()}")
        try:
            plan = Plan(instruction=text, objects=objects.objects(), subtasks=tuple(subtasks))
        except ValidationError as exc:  # steps that cannot follow each other (into a shut drawer)
            problems = "; ".join(str(e["msg"]).removeprefix("Value error, ") for e in exc.errors())
            raise PlanningError(f"cannot ground {bounded(text)}: {problems}") from None
        missing = self._missing(" ; ".join(clauses), plan.objects)
        if missing:  # a parse that lost an object would label the episode wrongly
            raise PlanningError(f"cannot ground {bounded(text)}: the steps read as {self._steps(subtasks)} "
                                f"but these named objects would be missing: {listed(missing)}; "
                                f"{self.capabilities()}")
        return self._capped(plan)

    def _clause(self, clause: str, objects: _Objects) -> Subtask:
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

    def _understood(self, clauses: list[str], subtasks: list[Subtask]) -> str:
        seen = listed(list(dict.fromkeys(m.label() for m in find_mentions(words(" ; ".join(clauses))))))
        done = f"; steps understood before it: {self._steps(subtasks)}" if subtasks else ""
        return f" (objects recognised: {seen}{done})"

    @staticmethod
    def _steps(subtasks: list[Subtask]) -> str:
        return "; ".join(f"{st.skill}({', '.join(f'{k}={v}' for k, v in st.args.items())})"
                         for st in subtasks)

    # -- library goals -----------------------------------------------------------------------------

    def match(self, text: str) -> list[Scored]:
        """Every goal scored against ``text``, best first (the confidence the threshold applies to).

        The names of catalog objects are left out unless they are goal words themselves ("bowl",
        "apple", "blocks"): whether a goal has the objects a sentence names is checked by looking at
        the goal's objects, not by how similar the words are."""
        ws = words(text)
        drop = {k for m in find_mentions(ws) for k in range(m.first, m.end)
                if not set(tokens(m.noun)) & self.matcher.vocabulary}
        return self.matcher.rank(" ".join(w for k, w in enumerate(ws) if k not in drop))

    def _goal(self, text: str, exact: bool) -> Plan:
        threshold = EXACT_MATCH if exact else self.threshold
        ranked = self.match(text)
        named = find_mentions(words(text))
        recognised = f"objects recognised: {listed(list(dict.fromkeys(m.label() for m in named)))}"
        near = ", ".join(f"{x.label} ({x.score:.2f})" for x in ranked[:3] if x.score > 0) or "none"
        fail = f"cannot ground {bounded(text, 120)}"  # with two 40-character phrases: 200 of the user's text
        count = _COUNT.search(text.lower())
        if count:
            raise PlanningError(f"{fail}: a goal does what its plan does, once; {count.group()!r} asks for a "
                                f"number of things the goal does not choose. Give explicit steps instead. "
                                f"{self.capabilities()}")
        unknown = self._unknown_phrases(text)
        if unknown:
            quoted = ", ".join(bounded(u, 40) for u in unknown[:2])
            raise PlanningError(f"{fail}: {quoted} is not an object or a goal the offline planner knows "
                                f"({recognised}; closest goals: {near}); {self.capabilities()}")
        if not ranked or ranked[0].score < threshold:
            raise PlanningError(f"{fail}: no goal matches well enough (closest goals: {near}; a goal needs "
                                f"a match of {threshold:.2f}; {recognised}); {self.capabilities()}")
        best = ranked[0]
        said = " ".join(words(text))  # a goal's own phrasing, word for word, is that goal
        verbatim = any(" ".join(words(p)) == said for p in self.goals[best.label].phrasings)
        rivals = [] if verbatim else [x for x in ranked[1:]
                                      if best.evidence <= self.matcher.vocabulary_of(x.label)]
        if rivals:
            raise PlanningError(f"{fail}: ambiguous, it fits {best.label} ({best.score:.2f}) and "
                                f"{rivals[0].label} ({rivals[0].score:.2f}), whose phrasings both hold every "
                                f"word it matched ({', '.join(sorted(best.evidence))}); say which. "
                                f"{self.capabilities()}")
        goal = self.goals[best.label]
        extra: dict[str, set[str]] = {}  # word -> every other goal whose name holds it
        for t in set(tokens(text)) - self.matcher.vocabulary_of(goal.name):
            for g, name in self._name_words.items():
                if g != goal.name and t in name:
                    extra.setdefault(t, set()).add(g)
        if extra:  # "clean the desk and the kitchen", "make breakfast and serve tea"
            also = sorted(set().union(*extra.values()))
            raise PlanningError(f"{fail}: it fits {goal.name} ({best.score:.2f}) but also asks for "
                                f"{', '.join(sorted(extra))}, words of {listed(also, 3)} that {goal.name} "
                                f"does not cover; give one goal per instruction. {self.capabilities()}")
        objects, missing = self._cover(goal.objects, named)
        if missing:
            have = ", ".join(_words(o) for o in goal.objects)
            raise PlanningError(f"{fail}: the closest goal {goal.name} ({best.score:.2f}) has no "
                                f"{listed(missing)} (its objects: {have}; {recognised}), so its plan "
                                f"would not do what the instruction says. Name only the goal, or give "
                                f"explicit steps; {self.capabilities()}")
        match = GoalMatch(score=round(best.score, 3), threshold=threshold,
                          alternatives=tuple((x.label, round(x.score, 3)) for x in ranked[1:3]))
        return self._capped(goal.plan(text, match=match, objects=objects))

    def _unknown_phrases(self, text: str) -> list[str]:
        """Noun phrases ("the laptop", "a song") none of whose words is an object or a goal word."""
        phrases = determiner_phrases(words(text), lambda w: w in PREPOSITIONS or not tokens(w))
        return [f"{det} {' '.join(run)}" for det, run in phrases
                if not any(r in self._known_words or set(tokens(r)) & self._known_words for r in run)]

    @staticmethod
    def _cover(objects: tuple[PlanObject, ...],
               named: list[Mention]) -> tuple[tuple[PlanObject, ...], list[str]]:
        """The goal's objects with the colours ``named`` gives them, and the mentions they miss."""
        objs = list(objects)
        chosen: set[int] = set()
        missing = []
        for m in named:
            if m.plural and not m.colours:
                if not any(o.type in m.accepts for o in objs):
                    missing.append(m.label())
                continue
            for colour in m.colours or (None,):
                hit = next((k for k, o in enumerate(objs) if o.type in m.accepts
                            and (colour is None or o.color == colour)), None)
                if hit is None and colour is not None:  # give an uncoloured object of the type this colour
                    hit = next((k for k, o in enumerate(objs) if o.type in m.accepts and o.color is None
                                and k not in chosen and colour in CATALOG.get(o.type).colors), None)
                    if hit is not None:
                        objs[hit] = objs[hit].model_copy(update={"color": colour})
                if hit is None:
                    missing.append(f"{colour} {m.noun}" if colour else m.noun)
                else:
                    chosen.add(hit)
        return tuple(objs), missing

    def _missing(self, text: str, objects: tuple[PlanObject, ...]) -> list[str]:
        return uncovered(text, objects)

    # -- limits and help ---------------------------------------------------------------------------

    def _capped(self, plan: Plan) -> Plan:
        if len(plan.subtasks) > self.max_subtasks:
            raise self._too_long(plan.instruction, len(plan.subtasks), "subtasks")
        return plan

    def _too_long(self, text: str, n: int, what: str) -> PlanningError:
        return PlanningError(
            f"{bounded(text)} has {n} {what}, more than the plan cap of {self.max_subtasks} subtasks; split "
            f"it into shorter instructions, or raise the cap: PlannerConfig(max_subtasks={n}), i.e. "
            f"\"max_subtasks\": {n} in the planner section of the run configuration")

    def capabilities(self) -> str:
        goals = "; ".join(f"{g.phrasings[0]}" for g in self.goals.values())
        return (f"the offline planner knows these goals: {goals}; and explicit sequences of at most "
                f"{self.max_subtasks} steps such as 'put the mouse on the mouse pad, then press the bell'. "
                "For anything else use an LLM planner (--planner llm with VCAGE_LLM_BASE_URL and "
                "VCAGE_LLM_MODEL set)")


__all__ = ["ALIASES", "EXACT_MATCH", "MATCH_THRESHOLD", "SIZES", "OfflinePlanner", "split_clauses"]
