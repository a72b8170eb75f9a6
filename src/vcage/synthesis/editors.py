"""Which image editor a synthesis run uses, as data, and the one factory that builds it.

``compositor`` (default) is the offline compositor with a perturbation preset; ``model`` is an image
model behind :mod:`vcage.backends.images`: ``backend.provider`` ``gemini`` (``generateContent``) or
``openai`` (any OpenAI-compatible ``/images/edits``). :meth:`EditorConfig.from_env` reads the
endpoint from ``VCAGE_IMAGE_*`` (provider, base URL, model, API key), like the planner's
``VCAGE_LLM_*``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from vcage.backends import BackendConfig
from vcage.config import from_fields
from vcage.errors import ConfigError
from vcage.synthesis.compositor import Compositor
from vcage.synthesis.editing import ImageEditor
from vcage.synthesis.model_editor import ModelEditor, ModelEditorConfig
from vcage.synthesis.perturb import PRESETS

ENV_PREFIX = "VCAGE_IMAGE"
NAMES = ("compositor", "model")


@dataclass(frozen=True)
class EditorConfig:
    name: str = "compositor"
    perturbation: str = "none"  # compositor: a preset of vcage.synthesis.perturb
    backend: BackendConfig | None = None  # model: the image model's endpoint
    model: ModelEditorConfig = field(default_factory=ModelEditorConfig)
    image_field: str = "image[]"  # openai: multipart field of the images, image[] or image
    response_format: str | None = None  # openai: b64_json for servers that answer with URLs by default

    def __post_init__(self) -> None:
        if self.name not in NAMES:
            raise ConfigError(f"unknown image editor {self.name!r}; valid: {', '.join(NAMES)}")
        if self.perturbation not in PRESETS:
            raise ConfigError(f"unknown perturbation {self.perturbation!r}; valid: {', '.join(PRESETS)}")
        if self.name == "model" and self.backend is None:
            raise ConfigError(f"the model editor needs a backend: set {ENV_PREFIX}_MODEL (and "
                              f"{ENV_PREFIX}_PROVIDER, {ENV_PREFIX}_BASE_URL) or pass one")

    @classmethod
    def from_env(cls, environ: Any = None, **backend: Any) -> EditorConfig:
        """A model editor whose endpoint comes from ``VCAGE_IMAGE_*``; ``backend`` overrides fields."""
        given = {k: v for k, v in backend.items() if v is not None}
        return cls(name="model", backend=BackendConfig.from_env(ENV_PREFIX, environ, **given))

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "perturbation": self.perturbation,
                "backend": self.backend.to_dict() if self.backend else None, "model": self.model.to_dict(),
                "image_field": self.image_field, "response_format": self.response_format}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> EditorConfig:
        return from_fields(cls, data, backend=BackendConfig, model=ModelEditorConfig)


def make_editor(cfg: EditorConfig) -> ImageEditor:
    """The editor ``cfg`` names; a model editor's backend is connected (no request is sent)."""
    if cfg.name == "compositor":
        return Compositor(PRESETS[cfg.perturbation])
    from vcage.backends.images import connect_images

    assert cfg.backend is not None
    options: dict[str, Any] = {}
    if cfg.backend.provider == "openai":
        options = {"image_field": cfg.image_field, "response_format": cfg.response_format}
    return ModelEditor(connect_images(cfg.backend, **options), cfg.model)
