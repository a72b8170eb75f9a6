"""Generative scene synthesis (the paper's stages 1-4): from a prompt to a settled, arranged scene.

Retrieval over the annotated catalog (:mod:`.retrieval`; an LLM chooser over its shortlist is not
built yet), the scene description ``D_scene`` (:mod:`.description`, built offline by
:mod:`.describe`), the top-down views (:mod:`.views`, :mod:`.camera`), goal images from an image
editor (:mod:`.editing`; offline: :mod:`.compositor` with :mod:`.perturb`), template matching
(:mod:`.matching`, the only OpenCV import), the refine objective (:mod:`.costs`, :mod:`.refine`),
settling (:mod:`.settle`) and the driver that runs them and writes the funnel (:mod:`.driver`).
Consumed by the pipeline and the CLI; imports neither.
"""

from vcage.synthesis.description import SceneDescription, SceneObject, SceneRelation, parse_description
from vcage.synthesis.errors import (
    ImageEditError,
    MatchingError,
    PromptError,
    RefineRejected,
    SceneDescriptionError,
    SettleRejected,
    SynthesisError,
)
from vcage.synthesis.retrieval import Hit, Retrieval, Retriever, retriever

__all__ = ["Hit", "ImageEditError", "MatchingError", "PromptError", "RefineRejected", "Retrieval",
           "Retriever",
           "SceneDescription", "SceneDescriptionError", "SceneObject", "SceneRelation", "SettleRejected",
           "SynthesisError", "parse_description", "retriever"]
