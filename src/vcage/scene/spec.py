"""Declarative description of a tabletop scene: table, lighting, cameras, and objects."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from vcage.errors import SceneError

ROBOT_MOUNT = (0.0, 0.0, 0.75)  # the Panda's base sits here, facing +x, at nominal table height


@dataclass(frozen=True)
class TableSpec:
    height: float = 0.75  # height of the top surface above the floor
    size: tuple[float, float] = (0.8, 1.2)  # x, y extent of the top
    center_x: float = 0.55
    rgba: tuple[float, float, float, float] = (0.62, 0.47, 0.33, 1.0)
    texture: str = "plain"  # "plain" | "checker" | "grid"
    thickness: float = 0.04

    def __post_init__(self) -> None:
        if not 0.5 <= self.height <= 1.0:
            raise SceneError(f"table height {self.height} m must lie in [0.5, 1.0]")
        if min(self.size) <= 0.2:
            raise SceneError(f"table size {self.size} must exceed 0.2 m on each side")
        if self.texture not in ("plain", "checker", "grid"):
            raise SceneError(f"table texture {self.texture!r}; valid: plain, checker, grid")

    @property
    def x_range(self) -> tuple[float, float]:
        return self.center_x - self.size[0] / 2, self.center_x + self.size[0] / 2

    @property
    def y_range(self) -> tuple[float, float]:
        return -self.size[1] / 2, self.size[1] / 2


@dataclass(frozen=True)
class ObjectSpec:
    """One object instance: catalog type and resting pose on the table (or at explicit ``z``)."""

    name: str
    type: str
    xy: tuple[float, float]
    yaw: float = 0.0
    scale: float = 1.0
    color: str | None = None
    friction: float = 1.0
    z: float | None = None  # absolute height of the object frame; default: on the table top

    def __post_init__(self) -> None:
        if "/" in self.name or not self.name:
            raise SceneError(f"object name {self.name!r} must be non-empty and contain no '/'")
        if not 0.3 <= self.scale <= 2.0:
            raise SceneError(f"object {self.name!r} scale {self.scale} must lie in [0.3, 2.0]")


@dataclass(frozen=True)
class SceneSpec:
    objects: tuple[ObjectSpec, ...] = ()
    table: TableSpec = field(default_factory=TableSpec)
    light: float = 0.8  # diffuse intensity of the key light
    camera_offset: tuple[float, float, float] = (0.0, 0.0, 0.0)  # jitter of the static cameras

    def __post_init__(self) -> None:
        names = [o.name for o in self.objects]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise SceneError(f"object names must be unique; repeated: {sorted(dup)}")

    def object(self, name: str) -> ObjectSpec:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise SceneError(f"no object {name!r} in the scene spec; objects: {[o.name for o in self.objects]}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SceneSpec:
        """The scene :meth:`to_dict` wrote (e.g. in a dataset's extras); bad data raises SceneError."""
        try:
            table = dict(data.get("table") or {})
            for key in ("size", "rgba"):
                if key in table:
                    table[key] = tuple(table[key])
            objects = []
            for obj in data.get("objects") or ():
                obj = dict(obj)
                obj["xy"] = tuple(obj["xy"])
                objects.append(ObjectSpec(**obj))
            rest = {k: v for k, v in data.items() if k not in ("objects", "table")}
            if "camera_offset" in rest:
                rest["camera_offset"] = tuple(rest["camera_offset"])
            return cls(objects=tuple(objects), table=TableSpec(**table), **rest)
        except (TypeError, KeyError, ValueError) as exc:
            raise SceneError(f"not a scene spec: {exc}") from exc
