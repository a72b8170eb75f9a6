"""Image editing over a model provider: an instruction and input images in, one image (or why not) out.

An :class:`ImageEditBackend` is a :class:`~vcage.backends.base.ChatBackend` of its provider (same
client, the same retry loop, circuit breaker, usage and preflight) that can also edit images. What
the transport cannot fix is retried there (timeouts, connection errors, 429 with the server's wait,
5xx); what the *model* answered is returned as an :class:`ImageAnswer` whose ``outcome`` says
whether an image came back: ``blocked`` (a safety or moderation refusal of the prompt or the image)
and ``no_image`` (a text-only answer, ``NO_IMAGE``, a URL instead of bytes) are answers, not
exceptions, so the caller can resample a bounded number of times. Providers register a factory in
:data:`IMAGE_PROVIDERS`; :func:`connect_images` builds the one for ``config.provider``. No MuJoCo.
"""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

from vcage.backends.base import ChatBackend
from vcage.errors import BackendError, ConfigError
from vcage.registry import Registry

if TYPE_CHECKING:
    from vcage.backends.config import BackendConfig

Outcome = Literal["image", "blocked", "no_image"]
OUTCOMES: tuple[str, ...] = ("image", "blocked", "no_image")


@dataclass(frozen=True)
class ImageAnswer:
    """What an image model answered: the final image's encoded bytes, or the reason there is none.

    ``image`` holds the file as sent (PNG, JPEG or WebP; decoding and checking it is the caller's);
    ``detail`` says why there is no image (a finish or block reason, the moderation message, the
    model's text); ``text`` is any text the model sent with it; ``thoughts`` counts interim
    "thought" images that were skipped because they are not the answer.
    """

    outcome: Outcome
    image: bytes | None = None
    mime_type: str | None = None
    detail: str = ""
    text: str = ""
    thoughts: int = 0

    def __post_init__(self) -> None:
        if self.outcome not in OUTCOMES:
            raise ValueError(f"unknown outcome {self.outcome!r}; valid: {', '.join(OUTCOMES)}")
        if (self.outcome == "image") != bool(self.image):
            raise ValueError("an 'image' outcome carries image bytes and no other outcome does")

    @classmethod
    def refused(cls, outcome: Outcome, detail: str, text: str = "", thoughts: int = 0) -> ImageAnswer:
        return cls(outcome=outcome, detail=detail, text=text, thoughts=thoughts)

    def to_dict(self) -> dict[str, Any]:
        """For logs: everything but the image bytes (their size instead)."""
        return {"outcome": self.outcome, "mime_type": self.mime_type, "bytes": len(self.image or b""),
                "detail": self.detail[:500], "text": self.text[:500], "thoughts": self.thoughts}


class ImageEditBackend(ChatBackend):
    """A provider's backend that also edits images with :meth:`edit`."""

    @property
    @abstractmethod
    def edit_url(self) -> str:
        """The URL edit requests go to, for messages and errors."""

    @abstractmethod
    def edit(self, prompt: str, images: Sequence[bytes], *, seed: int | None = None) -> ImageAnswer:
        """The model's answer to ``prompt`` about ``images`` (PNG bytes, the first one is edited).

        Raises :class:`~vcage.errors.BackendUnavailableError` when the endpoint cannot be reached
        or will not answer after the retries, :class:`~vcage.errors.BackendError` when it refused
        the request itself (e.g. 400 for a malformed request); a refusal of the *content* is an
        answer with outcome ``blocked``.
        """

    def _check_inputs(self, prompt: str, images: Sequence[bytes]) -> None:
        if not prompt.strip() or not images:
            raise BackendError("an image edit needs an instruction and at least one image",
                               endpoint=self.edit_url, model=self.config.model)


ImageBackendFactory = Callable[..., ImageEditBackend]
IMAGE_PROVIDERS: Registry[ImageBackendFactory] = Registry("image backend", error=ConfigError)


def _gemini(config: BackendConfig) -> ImageEditBackend:
    from vcage.backends.gemini_images import GeminiImageBackend

    return GeminiImageBackend(config)


def _openai(config: BackendConfig, **options: Any) -> ImageEditBackend:
    from vcage.backends.openai_images import OpenAIImageBackend

    return OpenAIImageBackend(config, **options)


IMAGE_PROVIDERS.add("gemini", _gemini)
IMAGE_PROVIDERS.add("openai", _openai)


def connect_images(config: BackendConfig, **options: Any) -> ImageEditBackend:
    """The image backend for ``config.provider``; ``options`` go to its constructor (openai:
    ``image_field``, ``response_format``, ``size``; gemini: none)."""
    factory = IMAGE_PROVIDERS.get(config.provider)
    try:
        return factory(config, **options)
    except TypeError as exc:
        raise ConfigError(f"image backend {config.provider!r} does not take the options "
                          f"{sorted(options)} ({exc})") from None
