"""From refined poses to a scene: a :class:`SceneSpec` with resting heights, settled and checked."""

from __future__ import annotations

from vcage.assets.catalog import CATALOG
from vcage.scene.instantiate import Instantiator, SceneConfig, SceneInstance
from vcage.scene.placement import PlacementStats
from vcage.scene.spec import ObjectSpec, SceneSpec, TableSpec
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.errors import SettleRejected

DROP = 0.002  # objects start this far above their support


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


def settle(spec: SceneSpec, seconds: float = 0.5) -> SceneInstance:
    """Compose and settle ``spec``; :class:`SettleRejected` unless it is physically valid."""
    inst = Instantiator(SceneConfig(settle_seconds=seconds)).realize(spec, PlacementStats("synthesis"))
    if not inst.valid:
        assert inst.stability is not None
        raise SettleRejected(f"the refined scene is not physically valid: {inst.stability.reason()}")
    return inst
