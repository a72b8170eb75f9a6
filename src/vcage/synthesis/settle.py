"""From refined poses to a scene: a :class:`SceneSpec` with resting heights, settled and checked."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.scene.compose import compose
from vcage.scene.instantiate import Instantiator, SceneConfig, SceneInstance
from vcage.scene.placement import PlacementStats
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec
from vcage.scene.stability import StabilityConfig, check_stability
from vcage.sim.world import World
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.errors import SettleRejected

DROP = 0.002  # objects start this far above their support
REST_SECONDS = 1.5  # physics time dropped objects get to come to rest before the scene is checked


def scene_spec(desc: SceneDescription, poses: dict[str, tuple[float, float, float]],
               table: TableSpec = TableSpec()) -> SceneSpec:
    rest: dict[str, float] = {}

    def height(name: str) -> float:
        if name not in rest:
            sup = desc.support_of(name)
            if sup is None:
                rest[name] = table.height
            else:
                host = desc.object(sup.b)
                kind = "on" if sup.kind == "on" else "in"
                place = next(p for p in CATALOG.get(host.type).placements if p.kind == kind)
                rest[name] = height(host.name) + place.pos[2] * host.scale
        return rest[name]

    objects = [ObjectSpec(o.name, o.type, (poses[o.name][0], poses[o.name][1]), poses[o.name][2], o.scale,
                          o.color, 1.0, height(o.name) + DROP) for o in desc.objects]
    return SceneSpec(objects=tuple(objects), table=table)


def settle(spec: SceneSpec, seconds: float = 0.5, desc: SceneDescription | None = None) -> SceneInstance:
    """Compose and settle ``spec``; :class:`SettleRejected` unless it is physically valid.

    An object resting on a support that is not flat where it rests (the slanted back of a phone
    stand) cannot start level on it. When ``desc`` says which objects rest on which and the scene
    as given is not valid, those objects are dropped instead from just above their support's top,
    the scene is left to come to rest (``REST_SECONDS``), and the rested scene is checked as any
    other: no interpenetration, nothing moving or falling, and each dropped object still on its
    support. ``inst.spec`` is then the spec they were dropped from; the world holds the rest state.
    """
    inst = Instantiator(SceneConfig(settle_seconds=seconds)).realize(spec, PlacementStats("synthesis"))
    if inst.valid:
        return inst
    assert inst.stability is not None
    reason = inst.stability.reason()
    dropped = _dropped(spec, desc) if desc is not None else None
    if dropped is not None:
        world = compose(dropped).make_world()
        world.settle(REST_SECONDS)
        report = check_stability(world, StabilityConfig(settle_seconds=seconds))
        off = [n for n, host in _supports(desc).items() if not rests_on(world, n, host)]  # type: ignore[arg-type]
        if report.ok and not off:
            return SceneInstance(dropped, world, PlacementStats("synthesis"), report)
        reason += (f"; dropped onto their supports instead: "
                   f"{report.reason() if not report.ok else 'off their supports: ' + ', '.join(off)}")
    raise SettleRejected(f"the refined scene is not physically valid: {reason}")


def _supports(desc: SceneDescription) -> dict[str, str]:
    return {r.a: r.b for r in desc.relations if r.kind == "on"}


def _dropped(spec: SceneSpec, desc: SceneDescription) -> SceneSpec | None:
    """``spec`` with every object resting ``on`` another raised to just above the host's top."""
    hosts = _supports(desc)
    by_name = {o.name: o for o in spec.objects}
    if not hosts or not all(h in by_name for h in hosts.values()):
        return None

    def top(name: str) -> float:
        o = by_name[name]
        base = o.z if o.z is not None else spec.table.height
        return base + CATALOG.get(o.type).size[2] * o.scale

    raised = tuple(replace(o, z=top(hosts[o.name]) + DROP) if o.name in hosts else o for o in spec.objects)
    return replace(spec, objects=raised)


def rests_on(world: World, name: str, host: str) -> bool:
    """``name``'s origin (at its base) lies over ``host``'s footprint, above half its surface's height."""
    pos, hpos = world.object_pos(name), world.object_pos(host)
    inst = world.objects[host]
    t = CATALOG.get(inst.type_name)
    surface = max((p.pos[2] for p in t.placements if p.kind == "on"), default=0.0) * inst.scale
    reach = 0.5 * float(np.hypot(t.size[0], t.size[1])) * inst.scale
    return bool(np.hypot(*(pos[:2] - hpos[:2])) <= reach and pos[2] > hpos[2] + 0.5 * surface)
