"""The scenes subtasks are found and verified in: an atomic task's scene or a ``SceneSpec`` file.

A scene is named by a reference: ``task:<name>`` or ``task:<name>@<seed>`` (the task's layout
placed for that seed, as an episode of the task would have it), a bare registered task name, or the
path of a ``scene_spec.json`` (what ``vcage synthesize`` writes) or of the directory holding one.
Its id is a hash of the spec, so the same scene is the same row however it was named.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from vcage.config import Randomization
from vcage.errors import ConfigError, SceneError
from vcage.scene.spec import SceneSpec
from vcage.subtasks.records import SceneRecord
from vcage.tasks.base import TASKS
from vcage.tasks.runner import make_task, place_scene

SPEC_FILE = "scene_spec.json"


def spec_digest(data: dict[str, Any]) -> str:
    """The SHA-256 (hex) of a scene spec's canonical JSON (``SceneSpec.to_dict()``)."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def scene_id(spec: SceneSpec) -> str:
    """A stable id of ``spec``: the first 12 hex digits of :func:`spec_digest`."""
    return spec_digest(spec.to_dict())[:12]


def task_scene(name: str, seed: int = 0) -> tuple[SceneRecord, SceneSpec]:
    """The placed scene of atomic task ``name`` for ``seed`` (randomised as the task's episodes are)."""
    task = make_task(name)
    place_scene(task, np.random.default_rng(seed), Randomization())
    assert task.spec is not None
    return SceneRecord(scene_id(task.spec), f"task:{name}@{seed}", task.spec.to_dict()), task.spec


def file_scene(path: Path) -> tuple[SceneRecord, SceneSpec]:
    """The scene in a ``scene_spec.json`` (or in the directory that holds one)."""
    file = path / SPEC_FILE if path.is_dir() else path
    try:
        data = json.loads(file.read_text())
    except (OSError, ValueError) as exc:
        raise SceneError(f"cannot read a scene spec from {file}: {exc}; pass a scene_spec.json written "
                         "by `vcage synthesize`, or task:<name>") from exc
    if not isinstance(data, dict):
        raise SceneError(f"{file} holds JSON {type(data).__name__}, not a scene spec object")
    spec = SceneSpec.from_dict(data)
    if not spec.objects:
        raise SceneError(f"the scene in {file} has no objects; nothing to manipulate")
    return SceneRecord(scene_id(spec), str(file), spec.to_dict()), spec


def resolve(ref: str) -> tuple[SceneRecord, SceneSpec]:
    """The scene a reference names (see the module's docstring)."""
    name, seed = ref, 0
    if ref.startswith("task:"):
        name = ref[len("task:"):]
        if "@" in name:
            name, _, tail = name.partition("@")
            try:
                seed = int(tail)
            except ValueError:
                raise ConfigError(f"scene {ref!r}: the seed after '@' must be an integer") from None
        TASKS.get(name)  # an unknown task lists the valid ones
        return task_scene(name, seed)
    if ref in TASKS:
        return task_scene(ref, seed)
    path = Path(ref)
    if not path.exists():
        raise ConfigError(f"scene {ref!r} is neither a task (task:<name>, `vcage tasks` lists them) nor an "
                          "existing scene_spec.json or directory holding one")
    return file_scene(path)
