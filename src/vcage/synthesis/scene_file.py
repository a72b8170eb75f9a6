"""A synthesized scene as a file generation can take: ``scene.json`` beside the synthesis artefacts.

It holds what generation needs and where it came from: the prompt, the run's seed and attempt,
each object (type, colour, scale, what it rests on or in) with its settled pose, the description's
relations, and the scene's editor. :func:`load_scene` reads it back (a directory or the file) and
records the file's SHA-256; :func:`ground_plan` binds a plan to it: every plan object to a scene
object of its type (and colour, if the plan names one), the scene's other objects joining the plan,
and the poses renamed to the plan's names. No MuJoCo import.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from vcage.errors import ConfigError
from vcage.planning.schema import Plan, PlanObject

if TYPE_CHECKING:
    from vcage.scene.instantiate import SceneInstance
    from vcage.synthesis.description import SceneDescription

KIND = "vcage.synthesized_scene"
VERSION = 1
FILE = "scene.json"


@dataclass(frozen=True)
class PlacedObject:
    name: str
    type: str
    x: float
    y: float
    yaw: float
    scale: float = 1.0
    color: str | None = None
    on: str | None = None  # the object it rests on or in (None: the table)


@dataclass(frozen=True)
class SynthesizedScene:
    """A synthesized scene and its provenance (``source`` and ``sha256`` are set when loaded)."""

    prompt: str
    objects: tuple[PlacedObject, ...]
    relations: tuple[str, ...] = ()
    seed: int = 0
    attempt: int = 0
    editor: str = "compositor"
    source: str | None = None
    sha256: str | None = None

    def __post_init__(self) -> None:
        names = [o.name for o in self.objects]
        if not names or len(set(names)) != len(names):
            raise ConfigError(f"a synthesized scene needs objects with unique names, got {names}")
        for o in self.objects:
            if not all(math.isfinite(v) for v in (o.x, o.y, o.yaw, o.scale)):
                raise ConfigError(f"object {o.name!r} of the synthesized scene has a non-finite pose")
            if o.on is not None and o.on not in names:
                raise ConfigError(f"object {o.name!r} rests on {o.on!r}, which the scene lacks")

    def object(self, name: str) -> PlacedObject | None:
        return next((o for o in self.objects if o.name == name), None)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": KIND, "version": VERSION, **asdict(self)}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SynthesizedScene:
        if not isinstance(data, dict) or data.get("kind", KIND) != KIND:
            raise ConfigError(f"not a synthesized scene (expected kind {KIND!r}); write one with "
                              "`vcage synthesize PROMPT --out DIR` and pass DIR/scene.json")
        if data.get("version", VERSION) != VERSION:
            raise ConfigError(f"synthesized scene version {data.get('version')} is not {VERSION}; "
                              "synthesize the scene again")
        fields: dict[str, Any] = {k: v for k, v in data.items() if k not in ("kind", "version")}
        try:
            fields["objects"] = tuple(PlacedObject(**o) for o in fields.get("objects", []))
            fields["relations"] = tuple(fields.get("relations", ()))
            return cls(**fields)
        except TypeError as exc:
            raise ConfigError(f"the synthesized scene is malformed: {exc}") from None


@dataclass(frozen=True)
class SynthesisRequest:
    """A scene to synthesize afresh for every episode attempt (seeded by the attempt): the prompt and
    the synthesis options that change the scene (see :class:`~vcage.synthesis.driver.SynthesisConfig`)."""

    prompt: str
    attempts: int = 3
    perturbation: str = "none"
    lam: float = 1.0

    def __post_init__(self) -> None:
        if not self.prompt.strip():
            raise ConfigError("the synthesis prompt is empty; say what the scene holds, e.g. 'organize the "
                              "breakfast table'")
        if isinstance(self.attempts, bool) or not isinstance(self.attempts, int) or self.attempts < 1:
            raise ConfigError(f"synthesis attempts must be an integer >= 1, got {self.attempts!r}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SynthesisRequest:
        try:
            return cls(**data)
        except TypeError as exc:
            raise ConfigError(f"the synthesis request is malformed: {exc}") from None


def load_scene(path: Path | str) -> SynthesizedScene:
    """The scene in ``path`` (a synthesis directory or its ``scene.json``), with its provenance."""
    path = Path(path)
    if path.is_dir():
        path = path / FILE
    try:
        raw = path.read_bytes()
        data = json.loads(raw)
    except (OSError, json.JSONDecodeError) as exc:
        raise ConfigError(f"cannot read the synthesized scene {path}: {exc}; pass the scene.json that "
                          "`vcage synthesize` wrote") from None
    scene = SynthesizedScene.from_dict(data)
    return replace(scene, source=str(path.resolve()), sha256=hashlib.sha256(raw).hexdigest())


def ground_plan(plan: Plan, scene: SynthesizedScene) -> tuple[Plan, SynthesizedScene]:
    """``plan`` on ``scene``'s objects: each plan object becomes the scene object of its type (and
    colour, if given), its colour, scale and support taken from the scene; the scene's other objects
    join the plan. Returns the plan and the scene renamed to the plan's names."""
    free = list(scene.objects)
    rename: dict[str, str] = {}
    for o in plan.objects:
        match = [s for s in free if s.type == o.type and (o.color is None or s.color == o.color)]
        if not match:
            what = f"{o.color + ' ' if o.color else ''}{o.type}"
            have = ", ".join(f"{s.color + ' ' if s.color else ''}{s.type}" for s in scene.objects)
            raise ConfigError(f"the plan needs a {what} ({o.name!r}), which the synthesized scene lacks "
                              f"(it has {have}); synthesize a scene with it, or change the instruction")
        chosen = next((s for s in match if s.name == o.name), match[0])
        free.remove(chosen)
        rename[chosen.name] = o.name
    taken = set(rename.values())
    for s in free:
        name, k = s.name, 2
        while name in taken:
            name, k = f"{s.name}_{k}", k + 1
        rename[s.name] = name
        taken.add(name)
    placed = tuple(replace(s, name=rename[s.name], on=rename[s.on] if s.on else None) for s in scene.objects)
    _refuse_goals_already_met(plan, placed, scene.prompt)
    objects = [PlanObject(name=p.name, type=p.type, color=p.color, scale=p.scale, on=p.on) for p in placed]
    grounded = Plan.model_validate({**plan.model_dump(), "objects": [o.model_dump() for o in objects]})
    return grounded, replace(scene, objects=placed)


def _refuse_goals_already_met(plan: Plan, placed: tuple[PlacedObject, ...], prompt: str) -> None:
    """A :class:`ConfigError` when a subtask's ``on`` / ``inside`` goal holds in the scene before
    anything has moved its object: the episode could only fail to place what is already there."""
    support = {p.name: p.on for p in placed}
    moved: set[str] = set()
    for i, st in enumerate(plan.subtasks):
        for p in st.predicates:
            if p.name in ("on", "inside") and p.args[0] not in moved and support.get(p.args[0]) == p.args[1]:
                raise ConfigError(
                    f"subtask {i} ({st.description!r}) asks for {p}, which already holds in the scene "
                    f"synthesized from {prompt!r}: the episode would have nothing to do there. Synthesize a "
                    f"scene where {p.args[0]} is elsewhere (e.g. beside {p.args[1]}), or change the "
                    "instruction")
        if isinstance(st.args.get("obj"), str):
            moved.add(st.args["obj"])


def yaw_of(quat: Any) -> float:
    w, x, y, z = (float(v) for v in quat)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def settled_scene(desc: SceneDescription, instance: SceneInstance, seed: int, attempt: int,
                  editor: str) -> SynthesizedScene:
    """The scene ``instance`` settled into, as generation takes it."""
    names = tuple(o.name for o in desc.objects)
    poses = instance.world.object_poses(names)
    objects = []
    for o, p in zip(desc.objects, poses, strict=True):
        support = desc.support_of(o.name)
        objects.append(PlacedObject(o.name, o.type, round(float(p[0]), 5), round(float(p[1]), 5),
                                    round(yaw_of(p[3:]), 5), o.scale, o.color,
                                    support.b if support is not None else None))
    return SynthesizedScene(desc.prompt, tuple(objects), tuple(str(r) for r in desc.relations), seed, attempt,
                            editor)
