"""The errors of policy training and evaluation, in vcage's one hierarchy; each says what to change."""

from __future__ import annotations

from vcage.errors import DatasetError, VcageError


class PolicyError(VcageError):
    """Training or evaluating a policy cannot go on as asked."""


class MissingFeatureError(DatasetError):
    """A dataset lacks a feature the policy needs; the message names it and the back-fill command."""


class TrainingDivergedError(PolicyError):
    """The loss became NaN or infinite; training stopped and the last good checkpoint was kept."""


class CheckpointError(PolicyError):
    """A checkpoint is missing, unreadable, or does not belong to this run or this vcage."""


class EnvironmentMismatchError(PolicyError):
    """A checkpoint's observations, actions or control rate differ from the evaluation environment's."""
