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


class BackendError(VcageError):
    """A model provider request failed (after any retries); says endpoint, model, status, what to check."""

    def __init__(
        self,
        message: str,
        *,
        endpoint: str | None = None,
        model: str | None = None,
        status: int | None = None,
    ) -> None:
        super().__init__(message)
        self.endpoint = endpoint
        self.model = model
        self.status = status


class BackendTimeout(BackendError):  # noqa: N818 - the name says what happened
    """A model provider did not answer within the configured timeout on any attempt."""


class BackendUnavailableError(BackendError):
    """A model endpoint cannot be reached or will not answer: connection refused, timeouts, 429 or 5xx
    after every retry, 401/403/404 (no retry fixes them), an open circuit breaker or a failed preflight.

    An outage, never a model's verdict: stop the run, fix the endpoint (the message says which, with
    the model, the HTTP status and the server's own message) and run again.
    """


class BackendUnavailableTimeout(BackendUnavailableError, BackendTimeout):  # noqa: N818 - as BackendTimeout
    """The endpoint did not answer within the timeout on any attempt: an outage and a timeout both."""


class EmptyReplyError(BackendError):
    """The server answered, but its reply holds no text (e.g. a refusal or a blocked candidate).

    A reply, not an outage: a critic counts it as a malformed answer.
    """


class MissingAPIKeyError(ConfigError):
    """No API key is configured for a remote endpoint; the message names the env var and config field."""


class DatasetError(VcageError):
    """A dataset cannot be written or read as asked: mismatched config, bad input or a corrupt file."""


class CorruptDatasetError(DatasetError):
    """A dataset's files are damaged (truncated, unreadable, missing or inconsistent with its metadata).

    The message names the files and episodes; ``vcage verify DATASET --repair`` drops a damaged tail.
    """


class PlanningError(VcageError):
    """An instruction cannot be grounded into a valid plan; the message says what the planner can do."""


class SandboxError(VcageError):
    """Generated code could not be run in the sandbox (the child process would not start, or answered
    outside its protocol); the message says what to check."""


class CodeRejectedError(SandboxError, ValueError):
    """Generated code failed the sandbox's static checks and was never run; the message names each
    violation with its line, so a model (or a person) can rewrite the program."""


class SubtaskError(VcageError, ValueError):
    """A candidate subtask is invalid: an unknown skill or object, a missing or extra argument, a
    number that is not finite or a position off the table; the message names the argument."""


class SubtaskStoreError(VcageError):
    """The subtask database cannot be used as asked; the message names the file and what to change."""


class SubtaskStoreLockedError(SubtaskStoreError):
    """Another process holds the subtask database's write lock for longer than the busy timeout."""


class SubtaskStoreReadOnlyError(SubtaskStoreError):
    """The subtask database file (or its directory, which holds the WAL files) is not writable."""


class CorruptSubtaskStoreError(SubtaskStoreError):
    """The subtask database file is not a readable SQLite database of vcage's schema."""
