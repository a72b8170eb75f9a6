"""Image editing with Gemini image models over ``generateContent`` (``google-genai``): image in, image out.

The request holds the instruction and the input images as inline parts and asks for ``TEXT`` and
``IMAGE`` modalities. The answer is read as Gemini sends it:

- a part with ``thought: true`` is an interim "thought" image (Gemini 3 shows its drafts) and never
  the answer; the answer is the last image part that is not a thought;
- ``promptFeedback.blockReason`` (no candidates) and the safety finish reasons (``IMAGE_SAFETY``,
  ``SAFETY``, ``PROHIBITED_CONTENT``...) are a ``blocked`` answer;
- ``NO_IMAGE``, ``IMAGE_OTHER`` and a text-only answer are a ``no_image`` answer.

Transport failures (429 with ``RetryInfo``, 5xx, timeouts) are retried by the chat backend's loop.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from google.genai import types

from vcage.backends.gemini import API_VERSION, GeminiChatBackend
from vcage.backends.images import ImageAnswer, ImageEditBackend

BLOCKING = frozenset({"SAFETY", "IMAGE_SAFETY", "PROHIBITED_CONTENT", "IMAGE_PROHIBITED_CONTENT",
                      "BLOCKLIST", "SPII", "RECITATION", "IMAGE_RECITATION", "MODEL_ARMOR"})
ANSWERED = frozenset({"STOP", "MAX_TOKENS", "FINISH_REASON_UNSPECIFIED", ""})


def _name(value: Any) -> str:
    """An SDK enum's name (``FinishReason.NO_IMAGE`` -> ``NO_IMAGE``), or the raw string it carried."""
    if value is None:
        return ""
    return str(getattr(value, "value", value)).upper()


def read_answer(response: types.GenerateContentResponse) -> ImageAnswer:
    """The final image of ``response``, or the typed reason there is none."""
    feedback = response.prompt_feedback
    if feedback is not None and feedback.block_reason is not None:
        why = _name(feedback.block_reason)
        message = f": {feedback.block_reason_message}" if feedback.block_reason_message else ""
        return ImageAnswer.refused("blocked", f"the prompt was blocked ({why}{message})")
    candidates = response.candidates or []
    if not candidates:
        return ImageAnswer.refused("no_image", "the answer has no candidates")
    cand = candidates[0]
    parts = (cand.content.parts if cand.content is not None else None) or []
    images = [p for p in parts if p.inline_data is not None and p.inline_data.data]
    final = [p for p in images if not p.thought]
    thoughts = len(images) - len(final)
    text = "".join(p.text or "" for p in parts if not p.thought).strip()
    finish = _name(cand.finish_reason)
    message = f": {cand.finish_message}" if cand.finish_message else ""
    if finish in BLOCKING:
        return ImageAnswer.refused("blocked", f"the answer was blocked (finish reason {finish}{message})",
                                   text, thoughts)
    if final and finish in ANSWERED:
        blob = final[-1].inline_data
        assert blob is not None and blob.data is not None
        return ImageAnswer("image", bytes(blob.data), blob.mime_type, text=text, thoughts=thoughts)
    if finish not in ANSWERED:
        why = f"finish reason {finish}{message}"
    elif text:
        why = f"the model answered with text only: {text[:300]!r}"
    elif thoughts:
        why = f"only {thoughts} interim thought image(s), no final image"
    else:
        why = "the answer has no image"
    return ImageAnswer.refused("no_image", why, text, thoughts)


class GeminiImageBackend(GeminiChatBackend, ImageEditBackend):
    """A Gemini image model (e.g. ``gemini-2.5-flash-image``) editing images over ``generateContent``."""

    name = "gemini-images"
    not_found_hint = "check the image model name (e.g. gemini-2.5-flash-image) and base_url"

    @property
    def edit_url(self) -> str:
        return self.endpoint

    def edit(self, prompt: str, images: Sequence[bytes], *, seed: int | None = None) -> ImageAnswer:
        self._check_inputs(prompt, images)
        cfg = self.config
        parts = [types.Part.from_text(text=prompt)]
        parts += [types.Part.from_bytes(data=png, mime_type="image/png") for png in images]
        generation = types.GenerateContentConfig(
            response_modalities=["TEXT", "IMAGE"], temperature=cfg.temperature, seed=seed,
            candidate_count=1)
        response = self._send(lambda: self._client.models.generate_content(
            model=cfg.model, contents=[types.Content(role="user", parts=parts)], config=generation),
            what="image edit request", url=self.edit_url)
        usage = response.usage_metadata
        self._count(prompt_tokens=getattr(usage, "prompt_token_count", 0) or 0,
                    completion_tokens=getattr(usage, "candidates_token_count", 0) or 0)
        return read_answer(response)


__all__ = ["API_VERSION", "GeminiImageBackend", "read_answer"]
