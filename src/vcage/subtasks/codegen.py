"""A model writes each candidate's code: a short program against the skill API, never run here.

The prompt gives the skill API (the plan skills' signatures and what they do), the read-only scene
queries, the rules of the sandbox's language, the subtask (description and success predicates) and
the scene's objects with their poses. The reply's program is checked the way verification will run
it: the sandbox's static allow-list, one sandboxed run against the nominal scene, and the parent's
check of every call it recorded. A failure is sent back with its message, at most ``max_repairs``
times; the last program is kept either way, so a candidate the model never got right is *recorded*
as rejected (invalid) by verification rather than silently dropped.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Sequence

from vcage.backends import ChatBackend, Message
from vcage.errors import SubtaskError
from vcage.sandbox import Limits, SceneSnapshot, run_program
from vcage.scene.spec import SceneSpec
from vcage.subtasks.calls import api, check_call
from vcage.subtasks.candidates import Candidate
from vcage.vocabulary import PLAN_SKILLS

MAX_REPAIRS = 2
RULES = ("Write plain Python statements only: assignments, if/for/while, arithmetic, lists, dicts and "
         "calls of the functions above (and abs, min, max, round, len, range, float, int, bool, str, list, "
         "tuple, dict, enumerate, zip, sum, sorted, reversed, any, all, print). No imports, no function or "
         "class definitions, no lambda, no try, no names or attributes starting with '_', no eval/exec/"
         "getattr/open, no str.format. Positions are metres in the world frame: x away from the robot, "
         "y to its left, z up.")


def system_prompt() -> str:
    skills = "\n".join(f"- {s.name}({s.signature()}): {s.doc}" for s in PLAN_SKILLS.values())
    return (
        "You write short Python programs that make a Franka Panda arm do one tabletop subtask. The "
        "program calls skill functions by keyword; each call plans and executes one motion.\n\n"
        f"Skills:\n{skills}\n\n"
        "Scene queries (read-only): pose(name) -> (x, y, z, yaw); position(name) -> (x, y, z); "
        "objects() -> list of object names; TABLE_X, TABLE_Y: the table's (min, max) extent; TABLE_Z: "
        "its height.\n\n"
        f"Rules: {RULES}\n\n"
        "Example, 'put the apple to the left of the bowl':\n"
        "b = position('bowl')\npick_and_place(obj='apple', xy=(b[0], b[1] + 0.14))\n\n"
        "Reply with the program only, in one ```python block."
    )


def user_prompt(description: str, predicates: Sequence[object], spec: SceneSpec) -> str:
    """The instruction and scene context of one subtask (``predicates`` as ``on(a, b)``)."""
    objects = "\n".join(f"- {o.name}: a {o.type.replace('_', ' ')} at x={o.xy[0]:.3f}, y={o.xy[1]:.3f}, "
                        f"yaw={o.yaw:.2f}" for o in spec.objects)
    preds = ", ".join(str(p) for p in predicates)
    return (f"Subtask: {description}\nIt succeeds when these hold afterwards: {preds}\n\n"
            f"Objects in the scene:\n{objects}")


def prompt(cand: Candidate, spec: SceneSpec) -> list[Message]:
    """The messages that ask for ``cand``'s program."""
    return [Message("system", system_prompt()), Message("user", user_prompt(cand.description, cand.predicates,
                                                                           spec))]


def prompt_hash(messages: Sequence[Message]) -> str:
    text = "\n\n".join(f"{m.role}: {m.text}" for m in messages)
    return hashlib.sha256(text.encode()).hexdigest()


def extract_program(reply: str) -> str:
    """The code of a reply: its first fenced block, else the reply itself (prose fails the check)."""
    m = re.search(r"```(?:python|py)?[ \t]*\n(.*?)```", reply, re.S)
    return (m.group(1) if m else reply).strip() + "\n"


def nominal_snapshot(spec: SceneSpec) -> SceneSnapshot:
    """The scene as its spec places it (no simulator): what a first dry run of a program sees."""
    objects = {o.name: (o.xy[0], o.xy[1], spec.table.height if o.z is None else o.z, o.yaw)
               for o in spec.objects}
    return SceneSnapshot(objects, spec.table.x_range, spec.table.y_range, spec.table.height)


def dry_run(code: str, spec: SceneSpec, limits: Limits = Limits()) -> str | None:
    """Why ``code`` would fail before any physics (static check, sandboxed run, argument checks),
    or None."""
    result = run_program(code, api(), nominal_snapshot(spec), limits)
    if not result.ok:
        return result.describe()
    if not result.calls:
        return "the program called no skill"
    try:
        for call in result.calls:
            check_call(call, spec)
    except SubtaskError as exc:
        return f"invalid skill call: {exc}"
    return None


class ProgramWriter:
    """Asks ``backend`` for a program per candidate, with a bounded repair loop."""

    def __init__(self, backend: ChatBackend, max_repairs: int = MAX_REPAIRS,
                 limits: Limits = Limits()) -> None:
        self.backend, self.max_repairs, self.limits = backend, max_repairs, limits
        self.replies = 0  # chat requests made, for the funnel

    @property
    def model(self) -> str:
        return self.backend.config.model

    def write(self, cand: Candidate, spec: SceneSpec) -> Candidate:
        """``cand`` with the model's program as its code (checked, repaired at most ``max_repairs``
        times; the last program is kept even if it still fails)."""
        messages = prompt(cand, spec)
        digest = prompt_hash(messages)
        code = ""
        for _ in range(self.max_repairs + 1):
            reply = self.backend.chat(messages)
            self.replies += 1
            code = extract_program(reply)
            problem = dry_run(code, spec, self.limits)
            if problem is None:
                break
            messages += [Message("assistant", reply),
                         Message("user", f"That program fails: {problem}\nReply with the corrected program "
                                         "only, in one ```python block.")]
        return cand.with_program(code, self.model, digest)
