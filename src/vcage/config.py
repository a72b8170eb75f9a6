"""Configuration values as frozen, validated data. No MuJoCo import."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, replace
from typing import Any

from vcage.errors import ConfigError


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


@dataclass(frozen=True)
class SimConfig:
    """Physics and control rates."""

    timestep: float = 0.002
    control_hz: float = 20.0
    max_qvel: float = 100.0  # rad/s or m/s; above this the simulation is declared unstable

    def __post_init__(self) -> None:
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
