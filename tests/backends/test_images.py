"""Image-editing backends: the real google-genai and openai SDKs over real HTTP to local servers that
speak Gemini's ``generateContent`` and OpenAI's multipart ``/v1/images/edits``, every failure included."""

from __future__ import annotations

import base64
import io
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from PIL import Image

from vcage.backends import BackendConfig
from vcage.backends.images import ImageAnswer, ImageEditBackend, connect_images
from vcage.errors import BackendError, BackendUnavailableError, ConfigError

from .fake_gemini import FakeGemini
from .fake_images import (
    FakeImagesOpenAI,
    gemini_answer,
    gemini_image,
    gemini_prompt_block,
    gemini_text_only,
    image_part,
    moderation_block,
    openai_image,
    openai_url_only,
)
from .fake_openai import Raw, Status


def png(color: tuple[int, int, int], size: tuple[int, int] = (8, 6)) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(np.full((size[1], size[0], 3), color, np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def b64decode(text: str) -> bytes:
    """What the SDK sent: base64, standard or URL-safe, padded or not."""
    return base64.b64decode(text.replace("-", "+").replace("_", "/") + "=" * (-len(text) % 4))


INIT, EMPTY, DRAFT, FINAL = png((10, 20, 30)), png((200, 200, 200)), png((255, 0, 0)), png((0, 255, 0))
_OPEN: list[ImageEditBackend] = []


@pytest.fixture(autouse=True)
def _close() -> Iterator[None]:
    yield
    while _OPEN:
        _OPEN.pop().close()


def backend(base_url: str, provider: str, **options: Any) -> ImageEditBackend:
    cfg = BackendConfig(base_url=base_url, model="image-model", provider=provider, timeout=2.0,
                        max_retries=2, backoff=0.01, max_backoff=0.5, breaker_failures=3)
    _OPEN.append(connect_images(cfg, **options))
    return _OPEN[-1]


@pytest.fixture()
def gemini() -> Iterator[FakeGemini]:
    with FakeGemini() as srv:
        yield srv


@pytest.fixture()
def images() -> Iterator[FakeImagesOpenAI]:
    with FakeImagesOpenAI() as srv:
        yield srv


# -- Gemini -----------------------------------------------------------------------------------------
def test_gemini_skips_thought_images_and_returns_the_final_one(gemini: FakeGemini) -> None:
    gemini.script(gemini_image(FINAL, thoughts=(DRAFT, DRAFT), text="Here it is."))
    b = backend(gemini.base_url, "gemini")
    answer = b.edit("move the cup left", [INIT, EMPTY], seed=7)
    assert answer.outcome == "image" and answer.image == FINAL and answer.mime_type == "image/png"
    assert answer.thoughts == 2 and answer.text == "Here it is."
    assert gemini.paths == ["/v1beta/models/image-model:generateContent"]
    (req,) = gemini.requests
    parts = req["contents"][0]["parts"]
    assert parts[0] == {"text": "move the cup left"}
    assert [b64decode(p["inlineData"]["data"]) for p in parts[1:]] == [INIT, EMPTY]
    gen = req["generationConfig"]
    assert gen["responseModalities"] == ["TEXT", "IMAGE"] and gen["seed"] == 7
    assert (b.usage.requests, b.usage.prompt_tokens, b.usage.completion_tokens) == (1, 300, 1290)


@pytest.mark.parametrize(("item", "outcome", "detail"), [
    (gemini_text_only("I cannot edit this."), "no_image", "text only: 'I cannot edit this.'"),
    (gemini_answer([{"text": "sorry"}], "NO_IMAGE"), "no_image", "NO_IMAGE"),
    (gemini_answer([], "IMAGE_SAFETY"), "blocked", "blocked (finish reason IMAGE_SAFETY)"),
    (gemini_answer([image_part(FINAL)], "IMAGE_PROHIBITED_CONTENT"), "blocked", "IMAGE_PROHIBITED_CONTENT"),
    (gemini_prompt_block("PROHIBITED_CONTENT", "not allowed"), "blocked",
     "prompt was blocked (PROHIBITED_CONTENT: not allowed)"),
    (gemini_answer([{"text": "draft", "thought": True}, image_part(DRAFT, thought=True)]), "no_image",
     "only 1 interim thought image"),
    (Raw(200, {"candidates": []}), "no_image", "no candidates"),
])
def test_gemini_imageless_and_blocked_answers_are_outcomes(gemini: FakeGemini, item: Raw, outcome: str,
                                                           detail: str) -> None:
    gemini.script(item)
    b = backend(gemini.base_url, "gemini")
    answer = b.edit("rearrange", [INIT])
    assert answer.outcome == outcome and answer.image is None
    assert detail in answer.detail
    assert b.usage.requests == 1 and b.usage.retries == 0  # an answer is not retried by the transport
    assert not b.breaker.is_open and b.breaker.failures == 0


def test_gemini_429_waits_for_retry_info_then_succeeds(gemini: FakeGemini) -> None:
    gemini.script(Status(429, "quota", retry_delay="0.2s"), Status(503, "overloaded"), gemini_image(FINAL))
    b = backend(gemini.base_url, "gemini")
    answer = b.edit("rearrange", [INIT])
    assert answer.image == FINAL
    assert b.usage.requests == 3 and b.usage.retries == 2
    assert b.usage.wait_s == pytest.approx(0.2 + 0.02)  # RetryInfo, then backoff * 2


def test_gemini_client_errors_are_not_retried_and_outages_are_unavailable(gemini: FakeGemini) -> None:
    gemini.script(Status(400, "image too large"))
    b = backend(gemini.base_url, "gemini")
    with pytest.raises(BackendError, match="image edit request .*HTTP 400: image too large") as err:
        b.edit("rearrange", [INIT])
    assert not isinstance(err.value, BackendUnavailableError) and b.usage.requests == 1
    gemini.script(Status(503), Status(503), Status(503))
    with pytest.raises(BackendUnavailableError, match="after 3 attempts"):
        b.edit("rearrange", [INIT])


# -- OpenAI-compatible /v1/images/edits -----------------------------------------------------------------
def test_openai_edit_sends_multipart_image_array_and_reads_b64_json(images: FakeImagesOpenAI) -> None:
    images.script(openai_image(FINAL))
    b = backend(images.base_url, "openai")
    answer = b.edit("move the cup left", [INIT, EMPTY])
    assert answer.outcome == "image" and answer.image == FINAL and answer.mime_type == "image/png"
    (req,) = images.requests
    assert images.content_types[0].startswith("multipart/form-data; boundary=")
    assert req["model"] == "image-model" and req["prompt"] == "move the cup left" and req["n"] == "1"
    assert req["files"] == {"image[]": [INIT, EMPTY]}
    assert "response_format" not in req  # gpt-image-1 refuses it; sent only when configured
    assert (b.usage.prompt_tokens, b.usage.completion_tokens) == (50, 272)


def test_openai_edit_single_image_field_and_response_format(images: FakeImagesOpenAI) -> None:
    images.script(openai_image(FINAL, output_format=None))
    b = backend(images.base_url, "openai", image_field="image", response_format="b64_json", size="512x512")
    assert b.edit("rearrange", [INIT, EMPTY]).image == FINAL
    (req,) = images.requests
    assert req["files"] == {"image": [INIT]} and req["response_format"] == "b64_json"
    assert req["size"] == "512x512"


@pytest.mark.parametrize(("item", "outcome", "detail"), [
    (moderation_block("rejected by the safety system"), "blocked",
     "moderation refused the request (moderation_blocked): rejected by the safety system"),
    (openai_url_only(), "no_image", "response_format='b64_json'"),
    (Raw(200, {"created": 1, "data": []}), "no_image", "no data"),
    (Raw(200, {"created": 1, "data": [{"b64_json": "%%% not base64"}]}), "no_image", "not valid base64"),
])
def test_openai_blocked_and_imageless_answers_are_outcomes(images: FakeImagesOpenAI, item: Raw, outcome: str,
                                                           detail: str) -> None:
    images.script(item)
    b = backend(images.base_url, "openai")
    answer = b.edit("rearrange", [INIT])
    assert answer.outcome == outcome and answer.image is None and detail in answer.detail
    assert b.usage.requests == 1 and b.usage.retries == 0 and b.breaker.failures == 0


def test_openai_retries_rate_limits_and_refuses_bad_requests(images: FakeImagesOpenAI) -> None:
    images.script(Status(429, "slow down", retry_after="0.1"), openai_image(FINAL))
    b = backend(images.base_url, "openai")
    assert b.edit("rearrange", [INIT]).image == FINAL
    assert b.usage.retries == 1 and b.usage.wait_s == pytest.approx(0.1)
    images.script(Status(400, "invalid image format"))
    with pytest.raises(BackendError, match=r"images/edits .*HTTP 400: invalid image format"):
        b.edit("rearrange", [INIT])
    assert b.usage.requests == 3  # not retried


def test_image_backend_options_and_inputs_are_checked(images: FakeImagesOpenAI) -> None:
    with pytest.raises(ConfigError, match="image_field"):
        backend(images.base_url, "openai", image_field="images")
    with pytest.raises(ConfigError, match="does not take"):
        backend(images.base_url, "gemini", image_field="image")
    b = backend(images.base_url, "openai")
    with pytest.raises(BackendError, match="at least one image"):
        b.edit("rearrange", [])
    assert images.requests == []
    with pytest.raises(ValueError, match="carries image bytes"):
        ImageAnswer("image")
