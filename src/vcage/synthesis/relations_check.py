"""Which relations of ``D_scene`` a settled scene really shows: the refine objective's hinges, read
on the poses the objects came to rest in, within a tolerance (settling moves objects a little).

A support (``on`` / ``inside``) holds when the object's origin is over its host's placement, as the
refine step asks, or, for an object dropped onto a slanted support, when it rests on its host; an
order, ``near`` or ``aligned`` relation when its hinge is within ``tolerance``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vcage.scene.spec import TableSpec
from vcage.synthesis.costs import Problem, relation_terms
from vcage.synthesis.description import SUPPORTS, SceneDescription

TOLERANCE = 0.005  # metres of hinge violation still counted as held


@dataclass(frozen=True)
class Held:
    relation: str
    violation: float  # metres
    held: bool

    def to_dict(self) -> dict[str, object]:
        return {"relation": self.relation, "violation_m": round(self.violation, 4), "held": self.held}


def relations_held(desc: SceneDescription, poses: dict[str, tuple[float, float, float]],
                   rests_on: dict[str, bool] | None = None, table: TableSpec = TableSpec(),
                   tolerance: float = TOLERANCE) -> list[Held]:
    """Each relation of ``desc`` in its order, with its violation at ``poses`` (x, y, yaw) and whether
    it held; ``rests_on`` says for supported objects whether they rest on their host (physics)."""
    problem = Problem.build(desc, table)
    ps = np.array([poses[n] for n in problem.names], dtype=float)
    values = relation_terms(problem, ps)
    supported = [problem.names[i] for i in np.nonzero(problem.parent >= 0)[0]]
    by_support = dict(zip(supported, values[:len(supported)], strict=True))
    others = iter(values[len(supported):])
    out = []
    for r in desc.relations:
        if r.kind in SUPPORTS:
            v = float(by_support[r.a])
            held = v <= tolerance or bool((rests_on or {}).get(r.a, False))
        else:
            v = float(next(others))
            held = v <= tolerance
        out.append(Held(str(r), v, held))
    return out
