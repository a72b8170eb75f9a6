"""Configuration values as frozen, validated data. No MuJoCo import."""

from __future__ import annotations

import math
import os
from dataclasses import asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any, TypeVar

from vcage.errors import ConfigError

C = TypeVar("C")

# What the renderer can do: every composed scene has these cameras and this offscreen buffer
# (width, height); `vcage.scene.compose` builds them and a test holds it to these names.
CAMERAS = ("front", "overview", "top", "panda/wrist")
OFFSCREEN_SIZE = (640, 480)
# How the renderer draws heavy visual meshes (the robot's): as shipped, or simplified once
# (`vcage.sim.lod`): a twelfth of the faces, the same outlines (`benchmarks/render_lod.py`).
MESH_DETAILS = ("full", "lod")


def from_fields(cls: type[C], data: Any, **nested: Any) -> C:
    """Build the dataclass ``cls`` from a dict as ``to_dict``/``asdict`` wrote it.

    Unknown keys are refused with the valid ones; lists become tuples; keys named in ``nested``
    are built with that class's ``from_dict`` (or recursively with this function).
    """
    if not isinstance(data, dict):
        raise ConfigError(f"{cls.__name__} needs a mapping of its fields, got {type(data).__name__}")
    known = [f.name for f in fields(cls)]  # type: ignore[arg-type]
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ConfigError(f"unknown {cls.__name__} keys {unknown}; valid keys: {known}")
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key in nested and isinstance(value, dict):
            sub = nested[key]
            value = sub.from_dict(value) if hasattr(sub, "from_dict") else from_fields(sub, value)
        elif isinstance(value, list):
            value = tuple(tuple(v) if isinstance(v, list) else v for v in value)
        kwargs[key] = value
    try:
        return cls(**kwargs)
    except TypeError as exc:
        raise ConfigError(f"{cls.__name__}: {exc}") from None


@dataclass(frozen=True)
class Range:
    """A closed interval ``[low, high]`` sampled uniformly; refused if empty or not finite."""

    low: float
    high: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high)):
            raise ConfigError(f"range bounds must be finite numbers, got [{self.low}, {self.high}]")
        if self.low > self.high:
            raise ConfigError(f"range low {self.low} is above high {self.high}; swap them")

    @classmethod
    def fixed(cls, value: float) -> Range:
        return cls(value, value)

    @property
    def width(self) -> float:
        return self.high - self.low

    def check_within(self, name: str, lo: float, hi: float) -> None:
        if self.low < lo or self.high > hi:
            raise ConfigError(
                f"{name} range [{self.low}, {self.high}] must lie within [{lo}, {hi}]"
            )


@dataclass(frozen=True)
class Randomization:
    """Seeded domain randomisation of a task scene; ``enabled=False`` turns every part off.

    Each range is an offset or factor applied around the task's nominal value.
    """

    enabled: bool = True
    object_xy: Range = field(default_factory=lambda: Range(-0.03, 0.03))  # metres
    object_yaw: Range = field(default_factory=lambda: Range(-0.5, 0.5))  # radians
    scale: Range = field(default_factory=lambda: Range(0.9, 1.1))  # factor on nominal size
    color: bool = True  # pick among the catalog's colour variants
    friction: Range = field(default_factory=lambda: Range(0.7, 1.3))  # factor on sliding friction
    table_height: Range = field(default_factory=lambda: Range(-0.03, 0.03))  # metres
    light: Range = field(default_factory=lambda: Range(0.6, 1.0))  # diffuse intensity
    camera_jitter: Range = field(default_factory=lambda: Range(-0.01, 0.01))  # metres per axis

    def __post_init__(self) -> None:
        self.object_xy.check_within("object_xy", -0.2, 0.2)
        self.object_yaw.check_within("object_yaw", -math.pi, math.pi)
        self.scale.check_within("scale", 0.5, 1.5)
        self.friction.check_within("friction", 0.2, 3.0)
        self.table_height.check_within("table_height", -0.2, 0.2)
        self.light.check_within("light", 0.0, 1.0)
        self.camera_jitter.check_within("camera_jitter", -0.1, 0.1)

    @classmethod
    def off(cls) -> Randomization:
        return cls(enabled=False)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Randomization:
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise ConfigError(
                f"unknown randomization keys {sorted(unknown)}; valid keys: {sorted(known)}"
            )
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if isinstance(value, (list, tuple)):
                if len(value) != 2:
                    raise ConfigError(f"randomization {key} needs [low, high], got {value!r}")
                kwargs[key] = Range(float(value[0]), float(value[1]))
            elif isinstance(value, dict):
                kwargs[key] = Range(**value)
            else:
                kwargs[key] = value
        return replace(cls(), **kwargs)


# Configs stored before ``SimConfig.noslip_iterations`` existed ran MuJoCo's no-slip solver this often.
LEGACY_NOSLIP_ITERATIONS = 3
_LEGACY_SIM_FIELDS = ("timestep", "control_hz", "max_qvel")  # what SimConfig held then


@dataclass(frozen=True)
class SimConfig:
    """Physics and control rates.

    ``noslip_iterations`` are MuJoCo's no-slip solver passes after each step. Off by default: in the
    plan scenes with clutter they cost most of a step (the solver needs the dense constraint matrix)
    and changed no scene check and no scripted outcome (``benchmarks/physics_settings.py``).
    """

    timestep: float = 0.002
    control_hz: float = 20.0
    max_qvel: float = 100.0  # rad/s or m/s; above this the simulation is declared unstable
    noslip_iterations: int = 0

    def __post_init__(self) -> None:
        noslip = self.noslip_iterations
        if isinstance(noslip, bool) or not isinstance(noslip, int) or noslip < 0:
            raise ConfigError(f"noslip_iterations must be an integer >= 0, got {noslip!r}")
        if not 1e-4 <= self.timestep <= 0.01:
            raise ConfigError(f"timestep {self.timestep} s must lie in [1e-4, 0.01]")
        if self.control_hz <= 0:
            raise ConfigError(f"control_hz must be positive, got {self.control_hz}")
        if self.substeps < 1 or abs(self.substeps * self.timestep * self.control_hz - 1) > 1e-6:
            raise ConfigError(
                f"control period 1/{self.control_hz} s must be a whole multiple of the timestep "
                f"{self.timestep} s"
            )

    @property
    def substeps(self) -> int:
        return round(1.0 / (self.control_hz * self.timestep))


    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimConfig:
        """Read a config. A complete one stored before ``noslip_iterations`` existed (every other
        field, not that one) ran with :data:`LEGACY_NOSLIP_ITERATIONS` and gets them back, so its
        runs reproduce; a partial one gets the defaults."""
        legacy = isinstance(data, dict) and set(_LEGACY_SIM_FIELDS) <= set(data)
        if legacy and "noslip_iterations" not in data:
            data = {**data, "noslip_iterations": LEGACY_NOSLIP_ITERATIONS}
        return from_fields(cls, data)


@dataclass(frozen=True)
class RenderConfig:
    """What is rendered: the cameras recorded as videos and their size, and the critic's views.

    Sizes are (width, height) and are checked against the renderer's offscreen buffer; video sizes
    must be even (H.264 4:2:0). ``mesh_detail`` is how both draw heavy visual meshes (one of
    :data:`MESH_DETAILS`); it never changes the physics.
    """

    cameras: tuple[str, ...] = ("front", "panda/wrist")
    size: tuple[int, int] = (128, 128)
    critic_size: tuple[int, int] = (320, 240)
    mesh_detail: str = "lod"

    def __post_init__(self) -> None:
        if not self.cameras:
            raise ConfigError("record at least one camera")
        unknown = [c for c in self.cameras if c not in CAMERAS]
        if unknown:
            raise ConfigError(f"unknown camera(s) {unknown}; cameras: {', '.join(CAMERAS)}")
        if len(set(self.cameras)) != len(self.cameras):
            raise ConfigError(f"cameras {list(self.cameras)} name one camera twice")
        for what, (w, h) in (("video size", self.size), ("critic view size", self.critic_size)):
            if not all(isinstance(v, int) and not isinstance(v, bool) for v in (w, h)):
                raise ConfigError(f"{what} {w}x{h} must be whole pixels")
            if not (0 < w <= OFFSCREEN_SIZE[0] and 0 < h <= OFFSCREEN_SIZE[1]):
                raise ConfigError(f"{what} {w}x{h} must be positive and at most the renderer's "
                                  f"{OFFSCREEN_SIZE[0]}x{OFFSCREEN_SIZE[1]}")
        if any(v % 2 for v in self.size):
            raise ConfigError(f"video size {self.size[0]}x{self.size[1]} must be even")
        if self.mesh_detail not in MESH_DETAILS:
            raise ConfigError(f"unknown mesh_detail {self.mesh_detail!r}; choose one of "
                              f"{', '.join(MESH_DETAILS)}")

    def to_dict(self) -> dict[str, Any]:
        return {"cameras": list(self.cameras), "size": list(self.size),
                "critic_size": list(self.critic_size), "mesh_detail": self.mesh_detail}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> RenderConfig:
        return from_fields(cls, data)


def cache_dir() -> Path:
    """Where vcage keeps what it computes once per machine (the arm's reach map, simplified meshes):
    ``$XDG_CACHE_HOME/vcage``, by default ``~/.cache/vcage``."""
    root = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(root) / "vcage"
