"""Long-horizon chains composed from verified subtasks of the database, as plans generation runs.

A chain is a sequence of accepted subtasks of one scene, in an order where each step leaves what
the earlier steps achieved in place and starts from a state its verification could vouch for:

- an object is moved at most once, and never after something was put on or in it (it would carry
  that object away and undo an earlier step);
- an object receives at most one object (the skill sets an object down at the centre of the
  target's placement, where the first one already stands);
- an object is pressed at most once; an object moved by an earlier step may later be a target or be
  pressed (a tower, a stapler moved then pressed: dependent steps the critic checks as it goes);
- nothing is put on or in an object that holds something at the start: generation places what rests
  there anew in every episode, clear of the room the hand needs to set the next object down, and a
  host too small for both has no room (verification saw only the scene's own arrangement).

Only template subtasks are chained: a plan step is a skill call, and a model-written program is
verified as a program, not as the call it stands for. :func:`compose` draws a chain of a given
length with a seeded random depth-first search (scenes and subtasks in a seeded order, so the same
database and seed give the same chain); :func:`rebuild` makes the same chain again from the ids a
dataset recorded. The scene becomes a :class:`~vcage.synthesis.scene_file.SynthesizedScene`, so
generation starts every episode from it (jittered as a task's items) exactly as from a scene of
``vcage synthesize``, and every step is verified by the critic again.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import ValidationError

from vcage.assets.catalog import CATALOG
from vcage.config import from_fields
from vcage.errors import ConfigError, SceneError, SubtaskStoreError
from vcage.planning.schema import Plan, PlanObject, Predicate, Subtask
from vcage.scene.spec import SceneSpec
from vcage.subtasks.records import ACCEPTED, TEMPLATE, SceneRecord, SubtaskRecord
from vcage.subtasks.scenes import spec_digest
from vcage.subtasks.store import SubtaskStore
from vcage.synthesis.scene_file import FILE as SCENE_FILE
from vcage.synthesis.scene_file import PlacedObject, SynthesizedScene, load_scene

EDITOR = "subtasks"  # the ``editor`` of a scene that came from the subtask database
RESTING = 0.003  # metres above the table top from which an object rests on another one
_PREDICATE = re.compile(r"^\s*([a-z_]+)\((.*)\)\s*$")


@dataclass(frozen=True)
class SubtaskChain:
    """Where a chain came from (stored with the dataset): the database, the scene's id, the
    subtasks' ids in order, and the seed that drew them."""

    db: str
    scene_id: str
    subtasks: tuple[str, ...]
    seed: int = 0

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data["subtasks"] = list(self.subtasks)
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SubtaskChain:
        return from_fields(cls, data)


@dataclass(frozen=True)
class Chain:
    """A composed chain: the plan of its steps, the scene it starts from, and its provenance."""

    plan: Plan
    scene: SynthesizedScene
    provenance: SubtaskChain
    records: tuple[SubtaskRecord, ...]


def _moved(r: SubtaskRecord) -> str | None:
    return str(r.parameters["obj"]) if r.skill != "press" and "obj" in r.parameters else None


def _target(r: SubtaskRecord) -> str | None:
    target = r.parameters.get("target")
    return str(target) if target is not None else None


@dataclass(frozen=True)
class SceneFacts:
    """What the chaining rules need of a scene: the objects that hold something at the start."""

    occupied: frozenset[str] = frozenset()


def compatible(chain: Sequence[SubtaskRecord], step: SubtaskRecord, facts: SceneFacts) -> bool:
    """Whether ``step`` may follow ``chain`` (the rules of the module's docstring)."""
    if step.id in {r.id for r in chain}:
        return False
    moved = {_moved(r) for r in chain} - {None}
    targets = [t for r in chain if (t := _target(r)) is not None]
    pressed = {str(r.parameters["obj"]) for r in chain if r.skill == "press"}
    obj, target = _moved(step), _target(step)
    if obj is not None and (obj in moved or obj in targets):
        return False
    if target is not None and (target in facts.occupied or target in targets):
        return False
    return not (step.skill == "press" and str(step.parameters["obj"]) in pressed)


def _search(records: Sequence[SubtaskRecord], length: int, facts: SceneFacts,
            rng: np.random.Generator, budget: list[int]) -> list[SubtaskRecord] | None:
    """A chain of ``length`` steps, trying the records in a seeded order at each depth (depth-first,
    at most ``budget[0]`` extensions tried in all)."""
    def extend(chain: list[SubtaskRecord]) -> list[SubtaskRecord] | None:
        if len(chain) == length:
            return chain
        for i in rng.permutation(len(records)):
            if budget[0] <= 0:
                return None
            budget[0] -= 1
            step = records[int(i)]
            if compatible(chain, step, facts):
                found = extend([*chain, step])
                if found is not None:
                    return found
        return None

    return extend([])


def longest(records: Sequence[SubtaskRecord], facts: SceneFacts, cap: int = 8, budget: int = 20_000) -> int:
    """The length of the longest chain (up to ``cap``) the records allow, found within ``budget``
    extensions tried (a lower bound when the budget runs out)."""
    best, tries = 0, [budget]

    def grow(chain: list[SubtaskRecord]) -> None:
        nonlocal best
        best = max(best, len(chain))
        for step in records:
            if best >= cap or tries[0] <= 0:
                return
            tries[0] -= 1
            if compatible(chain, step, facts):
                grow([*chain, step])

    grow([])
    return best


def chainable(store: SubtaskStore, scene_id: str | None = None) -> dict[str, list[SubtaskRecord]]:
    """The accepted template subtasks of each scene (of one scene if ``scene_id``), by scene id."""
    out: dict[str, list[SubtaskRecord]] = {}
    for r in store.subtasks(status=ACCEPTED, scene_id=scene_id):
        if r.source == TEMPLATE:
            out.setdefault(r.scene_id, []).append(r)
    return out


def compose(store: SubtaskStore, length: int = 3, seed: int = 0, scene_id: str | None = None) -> Chain:
    """A chain of ``length`` accepted subtasks from ``store`` (of scene ``scene_id``, else of a
    scene drawn with ``seed``), as a plan on that scene."""
    if isinstance(length, bool) or not isinstance(length, int) or not 1 <= length <= 12:
        raise ConfigError(f"chain length {length!r} must be an integer in [1, 12]")
    if scene_id is not None:
        store.scene(scene_id)  # an unknown scene id names the database
    by_scene = chainable(store, scene_id)
    if not by_scene:
        where = f"scene {scene_id}" if scene_id else "any scene"
        raise SubtaskStoreError(f"{store.path} holds no accepted template subtask of {where}; verify "
                                "some with `vcage subtasks verify`")
    rng = np.random.default_rng(seed)
    scenes = sorted(by_scene)
    for i in rng.permutation(len(scenes)):
        sid = scenes[int(i)]
        record = store.scene(sid)
        steps = _search(by_scene[sid], length, scene_facts(record), rng, [20_000])
        if steps is not None:
            provenance = SubtaskChain(str(store.path.resolve()), sid, tuple(r.id for r in steps), seed)
            return _chain(record, steps, provenance)
    found = ", ".join(f"{sid}: {longest(by_scene[sid], scene_facts(store.scene(sid)))}"
                      for sid in scenes[:12])
    found += ", ..." if len(scenes) > 12 else ""
    raise SubtaskStoreError(f"no chain of {length} verified subtasks in {store.path} (the longest chain "
                            f"per scene: {found}); ask for a shorter --chain, or verify subtasks of "
                            "scenes with more objects")


def rebuild(store: SubtaskStore, provenance: SubtaskChain) -> Chain:
    """The chain ``provenance`` names, from the same database (refused if it changed)."""
    record = store.scene(provenance.scene_id)
    steps = []
    for sid in provenance.subtasks:
        step, _ = store.get(sid)
        if step.status != ACCEPTED or step.scene_id != provenance.scene_id:
            raise SubtaskStoreError(f"subtask {sid} in {store.path} is no longer an accepted subtask of "
                                    f"scene {provenance.scene_id}; the chain cannot be rebuilt")
        steps.append(step)
    return _chain(record, steps, provenance)


def scene_facts(record: SceneRecord) -> SceneFacts:
    return SceneFacts(frozenset(o.on for o in scene_of(record).objects if o.on))


def _chain(record: SceneRecord, steps: Sequence[SubtaskRecord], provenance: SubtaskChain) -> Chain:
    scene = scene_of(record)
    instruction = ", then ".join(r.description for r in steps)
    scene = SynthesizedScene(instruction, scene.objects, scene.relations, provenance.seed, 0, EDITOR,
                             source=f"{provenance.db}#{record.id}", sha256=spec_digest(record.spec))
    try:
        plan = Plan(instruction=instruction,
                    objects=tuple(PlanObject(name=o.name, type=o.type, color=o.color,
                                             scale=o.scale, on=o.on)
                                  for o in scene.objects),
                    subtasks=tuple(Subtask(skill=r.skill, args=r.parameters, description=r.description,
                                           predicates=tuple(parse_predicate(p) for p in r.predicates))
                                   for r in steps))
    except ValidationError as exc:
        raise SubtaskStoreError(f"the chain {list(provenance.subtasks)} of scene {record.id} is not a valid "
                                f"plan: {exc.errors()[0]['msg']}") from None
    return Chain(plan, scene, provenance, tuple(steps))


def parse_predicate(text: str) -> Predicate:
    """A predicate as the database stores it, e.g. ``on(mouse, pad)``."""
    match = _PREDICATE.match(text)
    if match is None:
        raise SubtaskStoreError(f"stored predicate {text[:60]!r} is not of the form name(arg, ...)")
    args = tuple(a.strip() for a in match.group(2).split(",") if a.strip())
    try:
        return Predicate(name=match.group(1), args=args)
    except ValidationError as exc:
        raise SubtaskStoreError(f"stored predicate {text[:60]!r}: {exc.errors()[0]['msg']}") from None


def scene_of(record: SceneRecord) -> SynthesizedScene:
    """The scene of ``record`` as generation takes it: the ``scene.json`` that ``vcage synthesize``
    wrote beside its spec when there is one (it knows what rests on what), else the spec's objects,
    an object above the table top resting on the object under it."""
    source = Path(record.source)
    if source.name == "scene_spec.json" and (source.parent / SCENE_FILE).is_file():
        scene = load_scene(source.parent)
        spec_names = {o["name"] for o in record.spec.get("objects", [])}
        if {o.name for o in scene.objects} == spec_names:
            return scene
    spec = SceneSpec.from_dict(record.spec)
    top = spec.table.height
    objects = []
    for o in spec.objects:
        on = None
        if o.z is not None and o.z > top + RESTING:
            on = _support(spec, o.name)
        objects.append(PlacedObject(o.name, o.type, o.xy[0], o.xy[1], o.yaw, o.scale, o.color, on))
    return SynthesizedScene(record.source, tuple(objects))


def _support(spec: SceneSpec, name: str) -> str:
    """The object ``name`` rests on or in: the nearest one with a placement whose footprint holds it."""
    obj = spec.object(name)
    best: tuple[float, str] | None = None
    for o in spec.objects:
        otype = CATALOG.get(o.type)
        if o.name == name or not otype.placements:
            continue
        d = float(np.hypot(obj.xy[0] - o.xy[0], obj.xy[1] - o.xy[1]))
        if d <= max(otype.size[:2]) * o.scale / 2 and (best is None or d < best[0]):
            best = (d, o.name)
    if best is None:
        raise SceneError(f"object {name!r} of the stored scene rests above the table but on no object "
                         "with a placement; the scene cannot be rebuilt for generation")
    return best[1]
