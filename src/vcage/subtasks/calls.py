"""The parent's check of every skill call before MuJoCo sees it.

Calls come from a template or, recorded by the sandbox's child, from a generated program: either
way they are data to distrust. A call is accepted only for a skill a plan may call
(``vocabulary.PLAN_SKILLS``), with exactly its parameters, object arguments naming objects of the
scene, annotation names (placement, functional point, grasp) the object's type really has, finite
numbers in each parameter's range, and table positions on the table. Anything else raises
:class:`~vcage.errors.SubtaskError` naming the argument.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from vcage.assets.catalog import CATALOG
from vcage.errors import CatalogError, SubtaskError
from vcage.sandbox.protocol import Call, SkillSignature
from vcage.scene.spec import SceneSpec
from vcage.vocabulary import PLAN_SKILLS

# Ranges of the numeric parameters (inclusive).
RANGES = {"depth": (0.0, 0.03), "hold": (0.0, 3.0), "height": (0.0, 0.3), "distance": (0.0, 0.4)}
TABLE_MARGIN = 0.03  # a table position must lie this far inside the table's edge


@dataclass(frozen=True)
class SkillCall:
    """A checked call, ready for ``Skills.do(skill, **kwargs)``."""

    skill: str
    kwargs: Mapping[str, Any]


def api() -> list[SkillSignature]:
    """The skill API a program is written against: the plan skills' signatures."""
    return [SkillSignature(s.name, tuple(p.name for p in s.params),
                           tuple(p.name for p in s.params if p.required)) for s in PLAN_SKILLS.values()]


def check_call(call: Call, scene: SceneSpec) -> SkillCall:
    """``call`` as a :class:`SkillCall`, if every argument is valid in ``scene``."""
    if call.skill not in PLAN_SKILLS:
        raise SubtaskError(f"unknown skill {call.skill!r}; valid: {', '.join(PLAN_SKILLS)}")
    spec = PLAN_SKILLS.get(call.skill)
    try:
        spec.check_args(dict(call.args))
    except ValueError as exc:
        raise SubtaskError(str(exc)) from None
    types = {o.name: o.type for o in scene.objects}
    out: dict[str, Any] = {}
    for param in spec.params:
        if param.name not in call.args:
            continue
        value = call.args[param.name]
        if value is None and not param.required:
            continue
        where = f"{call.skill}({param.name}=...)"
        if param.names_object:
            if not isinstance(value, str) or value not in types:
                raise SubtaskError(f"{where}: {str(value)[:40]!r} is not an object of the scene; "
                                   f"objects: {sorted(types)}")
            out[param.name] = value
        elif param.name in ("placement", "point", "grasp_name"):
            out[param.name] = _annotation(call, param.name, value, types)
        elif param.name == "xy":
            out[param.name] = _table_xy(where, value, scene)
        elif param.name == "direction":
            d = _vector(where, value)
            if math.hypot(*d) < 1e-6:
                raise SubtaskError(f"{where}: the direction must be non-zero")
            out[param.name] = d
        elif param.name == "home":
            if not isinstance(value, bool):
                raise SubtaskError(f"{where}: must be true or false, got {str(value)[:40]!r}")
            out[param.name] = value
        else:
            out[param.name] = _number(where, value, *RANGES.get(param.name, (-1.0, 1.0)))
    return SkillCall(call.skill, out)


def _annotation(call: Call, name: str, value: Any, types: Mapping[str, str]) -> str:
    owner = call.args.get("target") if name == "placement" else call.args.get("obj")
    if not isinstance(value, str) or not isinstance(owner, str) or owner not in types:
        raise SubtaskError(f"{call.skill}({name}=...) must name an annotation of a scene object")
    otype = CATALOG.get(types[owner])
    try:
        if name == "placement":
            otype.placement(value)
        elif name == "point":
            otype.functional_point(value)
        elif not any(g.name == value for g in otype.grasps):
            raise CatalogError(f"{otype.name} has no grasp {value!r}; "
                               f"annotated: {[g.name for g in otype.grasps]}")
    except CatalogError as exc:
        raise SubtaskError(f"{call.skill}({name}={value[:40]!r}): {exc}") from None
    return value


def _number(where: str, value: Any, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SubtaskError(f"{where}: expected a number, got {str(value)[:40]!r}")
    x = float(value)
    if not math.isfinite(x):
        raise SubtaskError(f"{where}: {x} is not a finite number")
    if not lo <= x <= hi:
        raise SubtaskError(f"{where}: {x:g} is outside [{lo:g}, {hi:g}]")
    return x


def _vector(where: str, value: Any) -> tuple[float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise SubtaskError(f"{where}: expected two numbers (x, y), got {str(value)[:40]!r}")
    return _number(where, value[0], -10.0, 10.0), _number(where, value[1], -10.0, 10.0)


def _table_xy(where: str, value: Any, scene: SceneSpec) -> tuple[float, float]:
    x, y = _vector(where, value)
    (x0, x1), (y0, y1) = scene.table.x_range, scene.table.y_range
    m = TABLE_MARGIN
    if not (x0 + m <= x <= x1 - m and y0 + m <= y <= y1 - m):
        raise SubtaskError(f"{where}: ({x:.3f}, {y:.3f}) is off the table "
                           f"(x in [{x0 + m:.2f}, {x1 - m:.2f}], y in [{y0 + m:.2f}, {y1 - m:.2f}])")
    return x, y
