"""Local servers and scripted answers for image editing: Gemini ``generateContent`` with image parts,
and OpenAI's multipart ``/v1/images/edits``.

    from backends.fake_images import FakeImagesOpenAI, gemini_image, openai_image, moderation_block

    with FakeGemini() as server:            # (fake_gemini) answers scripted Raw items as they are
        server.script(gemini_image(png, thoughts=(draft,)), gemini_prompt_block("SAFETY"))
    with FakeImagesOpenAI() as server:
        server.script(moderation_block(), openai_image(png))
        server.requests[0]["files"]["image[]"]  # the uploaded files' bytes, per multipart field

Every helper returns a :class:`~fake_openai.Raw` item holding the answer as each API sends it.
"""

from __future__ import annotations

import base64
import email.parser
import email.policy
import time
from typing import Any

from .fake_openai import FakeOpenAI, Raw


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


# -- Gemini ---------------------------------------------------------------------------------------
def gemini_answer(parts: list[dict[str, Any]], finish: str | None = "STOP",
                  finish_message: str | None = None) -> Raw:
    """A ``generateContent`` answer with one candidate of ``parts``."""
    cand: dict[str, Any] = {"content": {"role": "model", "parts": parts}, "index": 0}
    if finish is not None:
        cand["finishReason"] = finish
    if finish_message is not None:
        cand["finishMessage"] = finish_message
    return Raw(200, {"candidates": [cand], "modelVersion": "gemini-image-fake",
                     "usageMetadata": {"promptTokenCount": 300, "candidatesTokenCount": 1290,
                                       "totalTokenCount": 1590}})


def image_part(data: bytes, *, thought: bool = False, mime: str = "image/png") -> dict[str, Any]:
    part: dict[str, Any] = {"inlineData": {"mimeType": mime, "data": _b64(data)}}
    if thought:
        part["thought"] = True
        part["thoughtSignature"] = _b64(b"sig")
    return part


def gemini_image(data: bytes, *, thoughts: tuple[bytes, ...] = (), text: str | None = None,
                 finish: str = "STOP") -> Raw:
    """Gemini 3 style: interim thought images (and thought text) first, then the final image."""
    parts: list[dict[str, Any]] = []
    for draft in thoughts:
        parts += [{"text": "Drafting the layout.", "thought": True}, image_part(draft, thought=True)]
    if text is not None:
        parts.append({"text": text})
    parts.append(image_part(data))
    return gemini_answer(parts, finish)


def gemini_text_only(text: str = "I rearranged the objects as you asked.") -> Raw:
    return gemini_answer([{"text": text}])


def gemini_prompt_block(reason: str = "SAFETY", message: str | None = None) -> Raw:
    """The prompt itself refused: no candidates, ``promptFeedback.blockReason``."""
    feedback: dict[str, Any] = {"blockReason": reason}
    if message is not None:
        feedback["blockReasonMessage"] = message
    return Raw(200, {"promptFeedback": feedback,
                     "usageMetadata": {"promptTokenCount": 300, "totalTokenCount": 300}})


# -- OpenAI images --------------------------------------------------------------------------------
def openai_image(data: bytes, *, output_format: str | None = "png") -> Raw:
    """An ``ImagesResponse`` with one ``b64_json`` image (as gpt-image-1 answers)."""
    payload: dict[str, Any] = {"created": int(time.time()), "data": [{"b64_json": _b64(data)}],
                               "usage": {"input_tokens": 50, "output_tokens": 272, "total_tokens": 322,
                                         "input_tokens_details": {"image_tokens": 40, "text_tokens": 10}}}
    if output_format is not None:
        payload["output_format"] = output_format
    return Raw(200, payload)


def openai_url_only(url: str = "https://example.invalid/img.png") -> Raw:
    return Raw(200, {"created": int(time.time()), "data": [{"url": url}]})


def moderation_block(message: str = "Your request was rejected by the safety system.") -> Raw:
    """OpenAI's moderation refusal: 400, code ``moderation_blocked``."""
    return Raw(400, {"error": {"message": message, "type": "image_generation_user_error", "param": None,
                               "code": "moderation_blocked"}})


def parse_multipart(raw: bytes, content_type: str) -> dict[str, Any]:
    """Form fields (text) and files (bytes, a list per field name) of a multipart/form-data body."""
    if not content_type.startswith("multipart/form-data"):
        raise ValueError(f"expected multipart/form-data, got {content_type!r}")
    head = f"Content-Type: {content_type}\r\nMIME-Version: 1.0\r\n\r\n".encode()
    message = email.parser.BytesParser(policy=email.policy.HTTP).parsebytes(head + raw)
    if not message.is_multipart():
        raise ValueError("the body is not multipart")
    fields: dict[str, Any] = {}
    files: dict[str, list[bytes]] = {}
    for part in message.iter_parts():
        name = part.get_param("name", header="content-disposition")
        payload = part.get_payload(decode=True) or b""
        if part.get_filename() is not None:
            files.setdefault(str(name), []).append(payload)
        else:
            fields[str(name)] = payload.decode()
    return {**fields, "files": files}


class FakeImagesOpenAI(FakeOpenAI):
    """An OpenAI-compatible server with ``POST /v1/images/edits`` (multipart), scripted like
    :class:`FakeOpenAI`; ``requests`` hold each request's form fields and ``files``."""

    def __init__(self, model: str = "gpt-image-fake") -> None:
        super().__init__(model)
        self.content_types: list[str] = []

    def serves(self, path: str) -> bool:
        return path.rstrip("/") == "/v1/images/edits"

    def parse(self, raw: bytes, content_type: str) -> dict[str, Any]:
        self.content_types.append(content_type)
        return parse_multipart(raw, content_type)
