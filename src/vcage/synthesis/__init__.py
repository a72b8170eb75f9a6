"""Generative scene synthesis (the paper's stages 1-4): from a prompt to a settled, arranged scene.

Retrieval over the annotated catalog (:mod:`.retrieval`; with an LLM, :mod:`.llm_chooser` chooses
from its shortlist), the scene description ``D_scene`` (:mod:`.description`, built offline by
:mod:`.describe` or by an LLM in :mod:`.llm_describe`, both through :mod:`.llm_reply`'s bounded
repair loop), the top-down views (:mod:`.views`, :mod:`.camera`), goal images from an image editor
(:mod:`.editing`; offline: :mod:`.compositor` with :mod:`.perturb`; online: :mod:`.model_editor`
over :mod:`vcage.backends.images`; chosen by :mod:`.editors`), template matching
(:mod:`.matching`, the only OpenCV import), the refine objective (:mod:`.costs`, :mod:`.refine`),
settling (:mod:`.settle`), the relations that hold afterwards (:mod:`.relations_check`), the
driver that runs them and writes the funnel (:mod:`.driver`) and the scene file generation takes
(:mod:`.scene_file`). Consumed by the pipeline and the CLI; imports neither.
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
