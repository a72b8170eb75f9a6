"""The scene for a whole plan: its objects placed context-aware in the work area, plus clutter.

Task objects go into :data:`WORK_AREA` (where the skills' experts are measured); distractors may
go anywhere within reach. Targets given as positions (``xy`` arguments) become reserved zones, so
clutter never occupies them.
"""

from __future__ import annotations

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.config import Randomization
from vcage.planning.schema import Plan, PlanObject
from vcage.scene.layout import (
    Distractors,
    LayoutObject,
    LayoutSpec,
    Region,
    Relation,
    ReservedZone,
    Support,
)
from vcage.scene.randomize import environment, object_look

# x 0.45..0.70, y -0.3..0.3 (metres): reachable for every skill, and clear of the arm's home pose
# in the top view, so that the critic sees the objects after each subtask
WORK_AREA = Region((0.575, 0.0), (0.125, 0.3))
TARGET_ZONE = 0.05  # half size of the zone kept free around a position target


def plan_layout(plan: Plan, rng: np.random.Generator, rand: Randomization, clutter: int = 0,
                work_area: Region = WORK_AREA) -> LayoutSpec:
    objects = []
    for o in _largest_first(plan):
        scale, color, friction = object_look(o.type, rng, rand, (o.color,) if o.color else None)
        if o.scale is not None:
            scale = o.scale
        support = Support(o.on) if o.on else Support()
        objects.append(LayoutObject(o.name, o.type, support=support,
                                    region=None if o.on else work_area, scale=scale, color=color,
                                    friction=friction))
    relations = tuple(Relation(r.kind, r.a, r.b, r.distance) for r in plan.relations)
    reserved = tuple(
        ReservedZone(f"subtask{i}", Region((float(st.args["xy"][0]), float(st.args["xy"][1])),
                                           (TARGET_ZONE, TARGET_ZONE)))
        for i, st in enumerate(plan.subtasks) if st.args.get("xy") is not None)
    return LayoutSpec(objects=tuple(objects), relations=relations, reserved=reserved,
                      distractors=Distractors(clutter), **environment(rng, rand))


def _largest_first(plan: Plan) -> list[PlanObject]:
    """Big footprints are the hardest to fit, so they are placed first (supports stay first)."""
    def area(o: PlanObject) -> float:
        sx, sy = CATALOG.get(o.type).size[:2]
        return sx * sy

    return sorted(plan.objects, key=lambda o: (o.on is not None, -area(o)))
