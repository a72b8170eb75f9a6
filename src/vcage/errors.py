"""The one error hierarchy of vcage. Every error says what to change."""

from __future__ import annotations


class VcageError(Exception):
    """Base class of every error vcage raises on purpose."""


class ConfigError(VcageError, ValueError):
    """A configuration value is invalid; the message names the field and the valid range."""


class RegistryError(VcageError, KeyError):
    """A name is unknown to a registry or registered twice."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class CatalogError(VcageError, KeyError):
    """An object type, category or annotation is not in the catalog."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class SceneError(VcageError):
    """A scene cannot be composed as specified."""


class PlacementError(SceneError):
    """Objects cannot be placed as specified: a constraint is impossible or the free space ran out."""


class UnstableSceneError(SceneError):
    """An instantiated scene is not physically valid: objects interpenetrate, move or fall."""


class SimulationError(VcageError):
    """The physics became unstable (NaN, exploding velocities); the episode must not be recorded."""


class SkillError(VcageError):
    """A skill cannot produce a plan (no reachable grasp, failed IK, unknown target)."""


class IKError(SkillError):
    """Inverse kinematics did not converge to the requested pose within tolerance."""


class UnreachableError(SkillError):
    """A target pose lies outside the robot's reachable workspace."""


class TaskError(VcageError):
    """A task is misconfigured or its scene cannot be built."""
