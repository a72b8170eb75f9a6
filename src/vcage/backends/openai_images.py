"""Image editing over any OpenAI-compatible ``/v1/images/edits`` endpoint (the ``openai`` SDK, multipart).

The input images go up as multipart files, under ``image`` (one file; what DALL-E 2 style servers
read) or ``image[]`` (a list; what ``gpt-image-1`` style servers read): ``image_field`` chooses.
The answer's ``data[0].b64_json`` is the image; ``response_format`` may ask for ``b64_json``
explicitly (servers that default to URLs need it; ``gpt-image-1`` refuses the parameter, so it is
sent only when set). A moderation refusal (400 with code ``moderation_blocked`` or
``content_policy_violation``) is a ``blocked`` answer; an answer with a URL and no bytes, or no
data, is ``no_image``. Transport failures are retried by the chat backend's loop.
"""

from __future__ import annotations

import base64
import binascii
from collections.abc import Sequence
from typing import Any

import openai

from vcage.backends.config import BackendConfig
from vcage.backends.images import ImageAnswer, ImageEditBackend
from vcage.backends.openai_compat import OpenAIChatBackend, _server_message
from vcage.errors import ConfigError

IMAGE_FIELDS = ("image", "image[]")
MODERATION_CODES = frozenset({"moderation_blocked", "content_policy_violation"})


def moderation_code(exc: openai.APIStatusError) -> str | None:
    """The moderation code of a refused request (e.g. ``moderation_blocked``), or None."""
    if exc.status_code != 400:
        return None
    body = exc.body if isinstance(exc.body, dict) else {}
    codes = {getattr(exc, "code", None), body.get("code"), (body.get("error") or {}).get("code")
             if isinstance(body.get("error"), dict) else None}
    found = codes & MODERATION_CODES
    return next(iter(found)) if found else None


def read_answer(response: Any) -> ImageAnswer:
    """The image of an ``ImagesResponse``, or the typed reason there is none."""
    data = getattr(response, "data", None) or []
    if not data:
        return ImageAnswer.refused("no_image", "the answer has no data")
    first = data[0]
    text = getattr(first, "revised_prompt", None) or ""
    if getattr(first, "b64_json", None):
        try:
            raw = base64.b64decode(first.b64_json, validate=True)
        except (binascii.Error, ValueError):
            return ImageAnswer.refused("no_image", "b64_json is not valid base64", text)
        if not raw:
            return ImageAnswer.refused("no_image", "b64_json is empty", text)
        fmt = getattr(response, "output_format", None) or "png"
        return ImageAnswer("image", raw, f"image/{fmt}", text=text)
    if getattr(first, "url", None):
        return ImageAnswer.refused("no_image", "the server answered with a URL, not b64_json: set "
                                   "response_format='b64_json' for this server", text)
    return ImageAnswer.refused("no_image", "the answer's first item has neither b64_json nor url", text)


class OpenAIImageBackend(OpenAIChatBackend, ImageEditBackend):
    """``images.edit`` through the ``openai`` SDK against ``config.base_url``."""

    name = "openai-images"
    not_found_hint = ("check base_url (OpenAI-compatible servers usually end in /v1), that the server "
                      "has /images/edits, and the image model name")

    def __init__(self, config: BackendConfig, image_field: str = "image[]",
                 response_format: str | None = None, size: str | None = None) -> None:
        if image_field not in IMAGE_FIELDS:
            raise ConfigError(f"image_field {image_field!r} is unknown; use one of {list(IMAGE_FIELDS)}")
        if response_format not in (None, "b64_json"):
            raise ConfigError(f"response_format {response_format!r}: only 'b64_json' (or none) is read")
        super().__init__(config)
        self.image_field = image_field
        self.response_format = response_format
        self.size = size

    @property
    def edit_url(self) -> str:
        return self.config.base_url.rstrip("/") + "/images/edits"

    def edit(self, prompt: str, images: Sequence[bytes], *, seed: int | None = None) -> ImageAnswer:
        """``seed`` is not part of the images API and is ignored."""
        self._check_inputs(prompt, images)
        files = [(f"image_{i}.png", png, "image/png") for i, png in enumerate(images)]
        request: dict[str, Any] = {"model": self.config.model, "prompt": prompt, "n": 1,
                                   "image": files if self.image_field == "image[]" else files[0]}
        if self.response_format is not None:
            request["response_format"] = self.response_format
        if self.size is not None:
            request["size"] = self.size

        def call() -> ImageAnswer:
            try:
                response = self._client.images.edit(**request)
            except openai.APIStatusError as exc:
                code = moderation_code(exc)
                if code is None:
                    raise
                return ImageAnswer.refused("blocked", f"moderation refused the request ({code}): "
                                           f"{_server_message(exc)}")
            usage = getattr(response, "usage", None)
            self._count(prompt_tokens=getattr(usage, "input_tokens", 0) or 0,
                        completion_tokens=getattr(usage, "output_tokens", 0) or 0)
            return read_answer(response)

        return self._send(call, what="image edit request", url=self.edit_url)
