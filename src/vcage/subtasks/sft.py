"""Supervised fine-tuning data: verified programs as conversational prompt-completion JSONL.

Each accepted subtask of the database becomes one example: ``prompt`` (the system message with the
skill API and the user message with the subtask's instruction and scene context, exactly what
:mod:`vcage.subtasks.codegen` asks a model) and ``completion`` (the assistant's program: the model's
verified program, or the template written as a program), with ``metadata`` (ids, task, source,
SR and interval). Examples are split **by task**, never by example, so no evaluation task leaks into
training: a task is the skill with the catalog types it acts on (``pick_and_place:bread>basket``),
and a task goes to ``eval.jsonl`` when the hash of its name (with ``seed``) falls in the
``eval_share``. No training happens here.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vcage.scene.spec import SceneSpec
from vcage.subtasks.codegen import system_prompt, user_prompt
from vcage.subtasks.records import ACCEPTED, TEMPLATE, SubtaskRecord
from vcage.subtasks.store import SubtaskStore
from vcage.subtasks.trial import template_calls


def task_of(record: SubtaskRecord, spec: SceneSpec) -> str:
    """The task a subtask is an instance of: its skill and the types of the objects it names."""
    types = {o.name: o.type for o in spec.objects}
    named = [types.get(str(record.parameters[k]), "?") for k in ("obj", "target") if k in record.parameters]
    return f"{record.skill}:{'>'.join(named)}"


def program_of(record: SubtaskRecord) -> str:
    """The program an example teaches: the model's verified code, or the template's call written out."""
    if record.source != TEMPLATE:
        return record.code
    return "".join(f"{c.skill}({', '.join(f'{k}={v!r}' for k, v in c.args.items())})\n"
                   for c in template_calls(record.code))


def in_eval(task: str, eval_share: float, seed: int = 0) -> bool:
    digest = hashlib.sha256(f"{seed}/{task}".encode()).digest()
    return int.from_bytes(digest[:8], "big") / 2**64 < eval_share


def example(record: SubtaskRecord, spec: SceneSpec, task: str) -> dict[str, Any]:
    return {
        "prompt": [{"role": "system", "content": system_prompt()},
                   {"role": "user", "content": user_prompt(record.description, record.predicates, spec)}],
        "completion": [{"role": "assistant", "content": program_of(record)}],
        "metadata": {"subtask_id": record.id, "scene_id": record.scene_id, "task": task,
                     "source": record.source, "model": record.model, "success_rate": record.success_rate,
                     "ci": [record.ci_low, record.ci_high], "trials": record.trials},
    }


@dataclass(frozen=True)
class SplitCounts:
    train: int
    eval: int
    train_tasks: tuple[str, ...]
    eval_tasks: tuple[str, ...]


def export_sft(store: SubtaskStore, out: Path, eval_share: float = 0.2, seed: int = 0) -> SplitCounts:
    """Write ``train.jsonl``, ``eval.jsonl`` and ``split.json`` (the tasks of each) under ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    specs: dict[str, SceneSpec] = {}
    rows: dict[str, list[str]] = {"train": [], "eval": []}
    tasks: dict[str, set[str]] = {"train": set(), "eval": set()}
    for record in store.subtasks(status=ACCEPTED):
        if record.scene_id not in specs:
            specs[record.scene_id] = SceneSpec.from_dict(store.scene(record.scene_id).spec)
        spec = specs[record.scene_id]
        task = task_of(record, spec)
        split = "eval" if in_eval(task, eval_share, seed) else "train"
        rows[split].append(json.dumps(example(record, spec, task), sort_keys=True))
        tasks[split].add(task)
    for split, lines in rows.items():
        (out / f"{split}.jsonl").write_text("".join(line + "\n" for line in lines))
    (out / "split.json").write_text(json.dumps({k: sorted(v) for k, v in tasks.items()}, indent=2))
    return SplitCounts(len(rows["train"]), len(rows["eval"]), tuple(sorted(tasks["train"])),
                       tuple(sorted(tasks["eval"])))
