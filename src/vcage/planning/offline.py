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

from pydantic import ValidationError

from vcage.assets.catalog import CATALOG
from vcage.errors import ConfigError, PlanningError
from vcage.planning.clauses import _is_step, split_clauses
from vcage.planning.config import MAX_SUBTASKS
from vcage.planning.goals import GOALS, Goal
from vcage.planning.language import Matcher, Scored, bounded, tokens
from vcage.planning.lexicon import (
    ALIASES,
    COLOURS,
    NOUN_WORDS,
    PREPOSITIONS,
    SIZES,
    Mention,
    determiner_phrases,
    find_mentions,
    listed,
    uncovered,
    words,
)
from vcage.planning.schema import GoalMatch, Plan, PlanObject, Subtask
from vcage.planning.steps import _clause, _Objects, _words

MATCH_THRESHOLD = 0.34  # lowest paraphrase score accepted as a goal
# a sentence that reads as explicit steps but does not parse may still *be* a goal's phrasing
EXACT_MATCH = 0.9
_NEGATION = re.compile(r"\b(?:not|never|without|except|nor|dont|instead)\b|n't\b")
# a goal does its fixed number of things: a count in a goal sentence asks for something else
_COUNT = re.compile(r"\b(?:\d+|two|three|four|five|six|seven|eight|nine|ten|twice|thrice|times|dozen"
                    r"|several|many)\b")



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
                subtasks.append(_clause(clause, objects))
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


__all__ = ["ALIASES", "EXACT_MATCH", "MATCH_THRESHOLD", "SIZES", "OfflinePlanner"]
