"""The LLM planner: any OpenAI-compatible chat model grounds the instruction into a ``Plan``.

The prompt gives the skill library, the predicates, the catalog and the plan schema with one
worked example. The reply must be JSON that validates as a :class:`Plan`; an invalid reply is sent
back with the validation errors, a bounded number of times, then :class:`PlanningError` is raised.
A plan longer than the cap (``max_subtasks``, stated in the prompt) is refused at once, not sent back
to be shortened: a shortened plan could leave out part of the instruction it is labelled with.
"""

from __future__ import annotations

import json
import re

from pydantic import ValidationError

from vcage.assets.catalog import CATALOG
from vcage.backends import ChatBackend, Message
from vcage.errors import ConfigError, PlanningError
from vcage.planning.config import MAX_SUBTASKS
from vcage.planning.goals import GOALS
from vcage.planning.language import bounded
from vcage.planning.lexicon import uncovered
from vcage.planning.schema import Plan, plan_json_schema
from vcage.vocabulary import PLAN_SKILLS, PREDICATES

MAX_REPAIRS = 2


def skill_library() -> str:
    return "\n".join(f"- {s.name}({s.signature()}): {s.doc}" for s in PLAN_SKILLS.values())


def predicate_lines() -> str:
    return "\n".join(f"- {p.name} ({p.arity[0]}..{p.arity[1]} objects): {p.meaning}"
                     for p in PREDICATES.values())


def catalog_lines() -> str:
    lines = []
    for t in CATALOG.values():
        holds = ", ".join(f"{p.kind} '{p.name}'" for p in t.placements)
        points = ", ".join(f.name for f in t.functional_points if f.joint)
        extra = (f"; holds objects {holds}" if holds else "") + (f"; pressable at {points}" if points else "")
        lines.append(f"- {t.name} ({t.category}): {t.description}; colours {', '.join(t.colors)}{extra}")
    return "\n".join(lines)


def system_prompt(max_subtasks: int = MAX_SUBTASKS) -> str:
    example = GOALS[0].plan(GOALS[0].phrasings[0]).model_dump(mode="json", exclude_none=True)
    return (
        "You plan tabletop manipulation for a Franka Panda arm. Turn the user's instruction into a "
        "JSON plan: the objects the scene needs (catalog types only, each with a unique name; `on` "
        "names an object it starts on), optional relations between them for the initial layout, and "
        f"an ordered list of 1 to {max_subtasks} subtasks (never more than {max_subtasks}: a longer plan "
        "is rejected, so one subtask per requested step, no extra ones). Each subtask calls one skill "
        "with arguments that name plan objects, says in one sentence what must be visibly true "
        "afterwards, and lists the predicates that define its success.\n\n"
        f"Skills:\n{skill_library()}\n\nPredicates:\n{predicate_lines()}\n\n"
        f"Catalog:\n{catalog_lines()}\n\n"
        f"JSON schema of the reply:\n{json.dumps(plan_json_schema(), separators=(',', ':'))}\n\n"
        f"Example for '{example['instruction']}':\n{json.dumps(example, separators=(',', ':'))}\n\n"
        "Reply with the JSON object only."
    )


class LLMPlanner:
    name = "llm"

    def __init__(self, backend: ChatBackend, max_repairs: int = MAX_REPAIRS,
                 max_subtasks: int = MAX_SUBTASKS) -> None:
        if max_subtasks < 1:
            raise ConfigError(f"max_subtasks must be >= 1 (the most subtasks a plan may have), "
                              f"got {max_subtasks}")
        self.backend = backend
        self.max_repairs = max_repairs
        self.max_subtasks = max_subtasks

    def plan(self, instruction: str) -> Plan:
        text = " ".join(instruction.split())
        if not re.search(r"[A-Za-z]{2,}", text):
            raise PlanningError(f"empty or unintelligible instruction {bounded(instruction)}: say what the "
                                "robot should do, e.g. 'put the mouse on the mouse pad'")
        messages = [Message("system", system_prompt(self.max_subtasks)), Message("user", text)]
        errors = ""
        for _ in range(self.max_repairs + 1):
            reply = self.backend.chat(messages, json_mode=True)
            try:
                data = json.loads(strip_fences(reply))
                if not isinstance(data, dict):
                    raise ValueError(f"the reply is a JSON {type(data).__name__}, not an object")
                data["instruction"] = text
                data.setdefault("goal", None)
                data.pop("match", None)  # a goal match is the offline planner's measure, not the model's
                plan = Plan.model_validate(data)
                missing = uncovered(text, plan.objects)
                if missing:  # the plan would carry the instruction as the label of something else
                    raise ValueError(f"the instruction names {', '.join(missing)}, but the plan has no "
                                     "such object; every object the instruction names must be in the plan")
            except (ValueError, ValidationError) as exc:
                errors = describe_problems(exc)
            else:
                return self._capped(plan)
            messages += [Message("assistant", reply),
                         Message("user", f"That reply is not a valid plan: {errors}\nReply again with "
                                         "only the corrected JSON object.")]
        raise PlanningError(
            f"the LLM planner gave no valid plan for {bounded(text)} after {self.max_repairs + 1} replies; "
            f"last problems: {errors}. Try a stronger model, or the offline planner's goals "
            "(`vcage tasks`)")

    def _capped(self, plan: Plan) -> Plan:
        n = len(plan.subtasks)
        if n > self.max_subtasks:
            raise PlanningError(
                f"the LLM planner's plan for {bounded(plan.instruction)} has {n} subtasks, more than "
                f"the plan cap of {self.max_subtasks}; split the instruction into shorter ones, or raise "
                f"the cap: PlannerConfig(max_subtasks={n}), i.e. \"max_subtasks\": {n} in the planner "
                "section of the run configuration")
        return plan


def strip_fences(text: str) -> str:
    """A model's reply without the Markdown code fence it may wrap JSON in."""
    m = re.search(r"```(?:json)?\s*(.*?)```", text, re.S)
    return m.group(1) if m else text.strip()


def describe_problems(exc: Exception, root: str = "plan", limit: int = 8) -> str:
    """What is wrong with a reply, in words a model can act on (``root`` names the whole reply)."""
    if isinstance(exc, ValidationError):
        return "; ".join(f"{'.'.join(str(p) for p in e['loc']) or root}: {e['msg']}"
                         for e in exc.errors()[:limit])
    if isinstance(exc, json.JSONDecodeError):
        return f"not valid JSON ({exc.msg} at line {exc.lineno} column {exc.colno})"
    return str(exc)
