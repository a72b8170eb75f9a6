"""The typed failures of scene synthesis, all in the :class:`~vcage.errors.VcageError` hierarchy.

Each says which stage refused what and what to change. "No suitable object" is not among them: it
is an answer of retrieval (:class:`~vcage.synthesis.retrieval.Retrieval` with no hits).
"""

from __future__ import annotations

from vcage.errors import VcageError


class SynthesisError(VcageError):
    """Scene synthesis could not produce a scene; ``stage`` names the stage that refused."""

    stage = "synthesis"


class PromptError(SynthesisError):
    """The prompt is empty, meaningless, or names objects the catalog lacks."""

    stage = "prompt"


class SceneDescriptionError(SynthesisError):
    """A scene description contradicts itself, names unknown objects or cannot fit on the table."""

    stage = "description"


class ImageEditError(SynthesisError):
    """The image-editing model gave no usable goal image (blocked, imageless, wrong size, garbage)."""

    stage = "edit"


class MatchingError(SynthesisError):
    """The goal image could not be registered to the initial image, or no object was found in it."""

    stage = "matching"


class RefineRejected(SynthesisError):  # noqa: N818 - a rejection, as the funnel says
    """The refine step found no collision-free pose set satisfying the description within its budget."""

    stage = "refine"


class SettleRejected(SynthesisError):  # noqa: N818 - a rejection, as the funnel says
    """The refined scene was not physically valid after settling (interpenetration, motion, a fall)."""

    stage = "settle"
