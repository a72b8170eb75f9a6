"""Subtasks a model proposes for a scene, beside the ones the catalog's annotations enumerate.

The model is shown the skill API, the predicates, the scene's objects with their annotations
(placements, functional points) and the template candidates already known, and answers with JSON:
``{"subtasks": [{"description", "skill", "args", "predicates": [{"name", "args"}]}]}``. Each
proposal is checked as a plan step (the skill's signature, the predicates' names and arities), as a
skill call in this scene (:func:`~vcage.subtasks.calls.check_call`: known objects and annotations,
finite numbers in range, positions on the table), and for predicates that name scene objects and
say something about the object the skill acts on. Problems are sent back item by item, at most
``max_repairs`` times; valid proposals are kept as they arrive. A proposal that repeats a known
candidate (same skill and arguments) is dropped and counted, not repaired.

A proposal becomes a :class:`~vcage.subtasks.candidates.Candidate` of template ``proposed`` whose
code is its skill call written as a program (``source="llm"``, with the model and the prompt's
hash): verification runs it in the sandbox like any model-written code, and the model's program
replaces it when ``--llm`` asks for programs too.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from vcage.assets.catalog import CATALOG
from vcage.backends import ChatBackend, Message
from vcage.errors import SubtaskError
from vcage.planning.llm import describe_problems, predicate_lines, skill_library, strip_fences
from vcage.planning.schema import Subtask
from vcage.sandbox.protocol import Call
from vcage.scene.spec import SceneSpec
from vcage.subtasks.calls import check_call
from vcage.subtasks.candidates import Candidate
from vcage.subtasks.codegen import prompt_hash

MAX_REPAIRS = 2
PROPOSED = "proposed"  # the template name of a model's proposal


def system_prompt(limit: int) -> str:
    example = {"subtasks": [{"description": "put the apple on the plate", "skill": "pick_and_place",
                             "args": {"obj": "apple", "target": "plate"},
                             "predicates": [{"name": "on", "args": ["apple", "plate"]},
                                            {"name": "released", "args": ["apple"]}]}]}
    return (
        "You propose subtasks a Franka Panda arm could do in a tabletop scene: each one skill call on "
        "the scene's objects, with the predicates that must hold afterwards for it to count as done. "
        f"Propose at most {limit}, each different from the known subtasks you are shown, each "
        "physically sensible (what the objects' annotations allow).\n\n"
        f"Skills:\n{skill_library()}\n\nPredicates:\n{predicate_lines()}\n\n"
        "Arguments name scene objects exactly; `placement`, `point` and `grasp_name` name annotations "
        "of that object; positions (`xy`) are metres in the world frame on the table.\n\n"
        f"Reply with one JSON object only, like:\n{json.dumps(example)}"
    )


def user_prompt(spec: SceneSpec, known: Sequence[Candidate]) -> str:
    lines = []
    for o in spec.objects:
        t = CATALOG.get(o.type)
        notes = [f"{p.kind} placement '{p.name}'" for p in t.placements]
        notes += [f"functional point '{f.name}' ({f.kind})" for f in t.functional_points if f.joint]
        notes += ["graspable"] if t.grasps and not t.fixed else []
        lines.append(f"- {o.name}: a {o.type.replace('_', ' ')} at x={o.xy[0]:.3f}, y={o.xy[1]:.3f}"
                     + (f"; {', '.join(notes)}" if notes else ""))
    (x0, x1), (y0, y1) = spec.table.x_range, spec.table.y_range
    done = "\n".join(f"- {c.description}: {c.skill}({json.dumps(c.args, sort_keys=True)})" for c in known)
    return (f"Objects in the scene:\n{chr(10).join(lines)}\n\nThe table spans x {x0:.2f}..{x1:.2f}, "
            f"y {y0:.2f}..{y1:.2f}.\n\nKnown subtasks (do not repeat them):\n{done or '- none'}")


@dataclass
class ProposalCounts:
    """What the model's answers amounted to: replies asked for, proposals received, valid ones
    kept, repeats of known subtasks dropped, and proposals still invalid after the repairs."""

    replies: int = 0
    proposed: int = 0
    valid: int = 0
    duplicates: int = 0
    invalid: int = 0
    problems: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, int]:
        return {"replies": self.replies, "proposed": self.proposed, "valid": self.valid,
                "duplicates": self.duplicates, "invalid": self.invalid}


def _key(skill: str, args: dict[str, Any]) -> str:
    return json.dumps([skill, args], sort_keys=True)


class SubtaskProposer:
    """Asks ``backend`` for up to ``limit`` new subtasks per scene, with a bounded repair loop."""

    def __init__(self, backend: ChatBackend, limit: int = 5, max_repairs: int = MAX_REPAIRS) -> None:
        if limit < 1:
            raise SubtaskError(f"the number of subtasks to propose must be >= 1, got {limit}")
        self.backend, self.limit, self.max_repairs = backend, limit, max_repairs

    def propose(self, scene_id: str, spec: SceneSpec, known: Sequence[Candidate]) -> tuple[list[Candidate],
                                                                                           ProposalCounts]:
        messages = [Message("system", system_prompt(self.limit)), Message("user", user_prompt(spec, known))]
        digest = prompt_hash(messages)
        seen = {_key(c.skill, c.args) for c in known}
        counts, out = ProposalCounts(), list[Candidate]()
        problems: list[str] = []
        for _ in range(self.max_repairs + 1):
            reply = self.backend.chat(messages, json_mode=True)
            counts.replies += 1
            problems = []
            try:
                items = _items(reply)
            except ValueError as exc:
                problems = [describe_problems(exc, root="reply")]
                items = []
            for i, item in enumerate(items):
                counts.proposed += 1
                try:
                    cand = self._candidate(scene_id, spec, item, digest)
                except (ValueError, SubtaskError) as exc:
                    problems.append(f"subtask {i}: {describe_problems(exc, root='subtask')}")
                    continue
                key = _key(cand.skill, cand.args)
                if key in seen:
                    counts.duplicates += 1
                    continue
                seen.add(key)
                if len(out) < self.limit:
                    out.append(cand)
            if not problems or len(out) >= self.limit:
                break
            messages += [Message("assistant", reply),
                         Message("user", "These proposals are not valid: " + "; ".join(problems)
                                 + "\nReply with corrected replacements for them only, as the same JSON "
                                   "object.")]
        counts.valid, counts.invalid, counts.problems = len(out), len(problems), problems
        return out, counts

    def _candidate(self, scene_id: str, spec: SceneSpec, item: Any, digest: str) -> Candidate:
        if not isinstance(item, dict):
            raise ValueError(f"expected an object with description, skill, args and predicates, got "
                             f"{type(item).__name__}")
        step = Subtask.model_validate({k: item.get(k) for k in ("skill", "args", "description", "predicates")
                                       if item.get(k) is not None})
        check_call(Call(step.skill, step.args), spec)
        names = {o.name for o in spec.objects}
        if not step.predicates:
            raise ValueError("a subtask needs at least one predicate that defines its success")
        unknown = sorted({a for p in step.predicates for a in p.args} - names)
        if unknown:
            raise ValueError(f"predicates name {unknown}, which are not scene objects")
        acted = step.args.get("obj")
        if acted is not None and not any(acted in p.args for p in step.predicates):
            raise ValueError(f"no predicate says anything about {acted!r}, the object the skill acts on")
        cand = Candidate(scene_id, PROPOSED, step.skill, dict(step.args), step.description, step.predicates,
                         objects=tuple(dict.fromkeys(step.objects())))
        return cand.with_program(cand.program_text(), self.backend.config.model, digest)


def _items(reply: str) -> list[Any]:
    data = json.loads(strip_fences(reply))
    if isinstance(data, dict) and isinstance(data.get("subtasks"), list):
        return list(data["subtasks"])
    raise ValueError('the reply must be a JSON object {"subtasks": [...]}')
