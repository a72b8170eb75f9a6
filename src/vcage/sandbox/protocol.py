"""What passes between the parent and the sandbox's child: plain JSON, never a pickle.

The parent sends the program, the skill API (names and parameters, no behaviour), a snapshot of the
scene (object poses, the table's extent) and the limits. The child answers with the skill calls
the program recorded, or the error that stopped it. :func:`parse_answer` reads that answer
strictly: anything else is a protocol error, reported as the run's outcome, never trusted.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

# How a run ended; "ok" is the only one with calls.
OK, REJECTED, RUNTIME, BLOCKED, MEMORY, CPU, TIMEOUT, CRASHED, BAD_OUTPUT = (
    "ok", "rejected", "runtime_error", "blocked", "memory_limit", "cpu_limit", "timeout", "crashed",
    "bad_output")
STATUSES = (OK, REJECTED, RUNTIME, BLOCKED, MEMORY, CPU, TIMEOUT, CRASHED, BAD_OUTPUT)
QUERIES = ("pose", "position", "objects", "TABLE_X", "TABLE_Y", "TABLE_Z")  # what a program may read


@dataclass(frozen=True)
class SkillSignature:
    """A skill as the child knows it: its name and parameters, no behaviour."""

    name: str
    params: tuple[str, ...]
    required: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "params": list(self.params), "required": list(self.required)}


@dataclass(frozen=True)
class SceneSnapshot:
    """What a program may read of the scene: each object's (x, y, z, yaw) and the table's extent."""

    objects: Mapping[str, tuple[float, float, float, float]]
    table_x: tuple[float, float]
    table_y: tuple[float, float]
    table_z: float

    def to_dict(self) -> dict[str, Any]:
        return {"objects": {k: list(v) for k, v in self.objects.items()}, "table_x": list(self.table_x),
                "table_y": list(self.table_y), "table_z": self.table_z}


@dataclass(frozen=True)
class Call:
    """One skill call a program recorded; its arguments are JSON data, not yet validated."""

    skill: str
    args: Mapping[str, Any]

    def to_dict(self) -> dict[str, Any]:
        return {"skill": self.skill, "args": dict(self.args)}


@dataclass(frozen=True)
class RunResult:
    """How one sandboxed run ended: ``status`` (one of :data:`STATUSES`), the recorded calls (when
    ``ok``), the error and its line otherwise, the program's print output and the wall time."""

    status: str
    calls: tuple[Call, ...] = ()
    error: str = ""
    line: int | None = None
    log: tuple[str, ...] = ()
    seconds: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict, compare=False)

    @property
    def ok(self) -> bool:
        return self.status == OK

    def describe(self) -> str:
        where = f" at line {self.line}" if self.line else ""
        return "ok" if self.ok else f"{self.status}{where}: {self.error}"


def request(code: str, api: Sequence[SkillSignature], scene: SceneSnapshot,
            limits: Mapping[str, float]) -> bytes:
    return json.dumps({"code": code, "api": [s.to_dict() for s in api], "scene": scene.to_dict(),
                       "limits": dict(limits)}).encode()


def _nonfinite(text: str) -> float:
    return {"NaN": math.nan, "Infinity": math.inf, "-Infinity": -math.inf}[text]


def parse_answer(stdout: bytes, seconds: float) -> RunResult:
    """The child's one JSON line as a :class:`RunResult`; malformed answers are ``bad_output``."""
    try:
        data = json.loads(stdout.decode("utf-8", "replace"), parse_constant=_nonfinite)
        if not isinstance(data, dict) or not isinstance(data.get("ok"), bool):
            raise ValueError("the answer is not an object with a boolean 'ok'")
        if data["ok"]:
            calls = tuple(_call(c) for c in _list(data.get("calls")))
            log = tuple(str(x) for x in _list(data.get("log")))
            return RunResult(OK, calls, log=log, seconds=seconds)
        kind = str(data.get("error_type", ""))
        line = data.get("line")
        status = (MEMORY if kind == "MemoryError" else BLOCKED if kind == "PermissionError" else RUNTIME)
        return RunResult(status, error=f"{kind}: {data.get('error', '')}"[:600],
                         line=line if isinstance(line, int) else None, seconds=seconds)
    except (ValueError, TypeError, KeyError) as exc:
        return RunResult(BAD_OUTPUT, error=f"the child's answer is not the protocol's JSON: {exc}"[:300],
                         seconds=seconds)


def _list(value: Any) -> list[Any]:
    if not isinstance(value, list):
        raise ValueError(f"expected a list, got {type(value).__name__}")
    return value


def _call(item: Any) -> Call:
    if not (isinstance(item, dict) and set(item) == {"skill", "args"} and isinstance(item["skill"], str)
            and isinstance(item["args"], dict)):
        raise ValueError(f"a call must be {{'skill': str, 'args': object}}, got {str(item)[:80]}")
    return Call(item["skill"], dict(item["args"]))
