"""Chat backend for any OpenAI-compatible endpoint (vLLM, Ollama, LM Studio, hosted APIs).

Retries are done by :class:`ChatBackend`, not by the SDK, so they are counted and bounded: timeouts,
connection errors, 429 and 5xx are retried with exponential backoff (or the server's ``Retry-After``),
capped by ``max_backoff``; other 4xx fail at once. ``preflight`` lists ``GET {base_url}/models`` and
checks the configured model is among them.
"""

from __future__ import annotations

import base64
from collections.abc import Sequence
from typing import Any

import openai

from vcage.backends.base import ChatBackend
from vcage.backends.config import BackendConfig
from vcage.backends.messages import Message
from vcage.backends.retry import Failure, retry_after_seconds
from vcage.errors import BackendError


def message_payload(message: Message) -> dict[str, Any]:
    """The chat-completions form of ``message``; images become base64 PNG ``image_url`` parts."""
    if not message.images:
        return {"role": message.role, "content": message.text}
    parts: list[dict[str, Any]] = [{"type": "text", "text": message.text}] if message.text else []
    for png in message.images:
        url = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
        parts.append({"type": "image_url", "image_url": {"url": url}})
    return {"role": message.role, "content": parts}


def _server_message(exc: openai.APIStatusError) -> str:
    body = exc.body
    if isinstance(body, dict) and isinstance(body.get("message"), str):
        return body["message"]
    if isinstance(body, str) and body.strip():
        return body.strip()[:500]
    return exc.message


class OpenAIChatBackend(ChatBackend):
    """Chat completions through the ``openai`` SDK against ``config.base_url``; registered as ``openai``
    (the class is its own factory) in :mod:`vcage.backends.builtin`."""

    name = "openai"
    not_found_hint = "check base_url (OpenAI-compatible servers usually end in /v1) and the model name"

    def __init__(self, config: BackendConfig) -> None:
        super().__init__(config)
        self._client = openai.OpenAI(
            base_url=config.base_url,
            api_key=config.resolve_api_key(),  # raises MissingAPIKeyError before any request
            timeout=config.timeout,
            max_retries=0,
        )

    @property
    def endpoint(self) -> str:
        return self.config.base_url.rstrip("/") + "/chat/completions"

    @property
    def probe_url(self) -> str:
        return self.config.base_url.rstrip("/") + "/models"

    def close(self) -> None:
        self._client.close()

    def _probe(self) -> list[str]:
        """``GET {base_url}/models``: what every OpenAI-compatible server lists (vLLM, Ollama, ...)."""
        return [m.id for m in self._client.models.list()]

    def chat(self, messages: Sequence[Message], *, json_mode: bool = False) -> str:
        if not messages:
            raise BackendError("chat needs at least one message", endpoint=self.endpoint,
                               model=self.config.model)
        request: dict[str, Any] = {
            "model": self.config.model,
            "messages": [message_payload(m) for m in messages],
            "temperature": self.config.temperature,
        }
        if self.config.max_tokens is not None:
            request["max_tokens"] = self.config.max_tokens
        if json_mode:
            request["response_format"] = {"type": "json_object"}
        response = self._send(lambda: self._client.chat.completions.create(**request))
        usage = getattr(response, "usage", None)
        choices = getattr(response, "choices", None)
        return self._reply(response, choices[0].message.content if choices else None,
                           getattr(usage, "prompt_tokens", 0) or 0,
                           getattr(usage, "completion_tokens", 0) or 0)

    def _failure(self, exc: Exception) -> Failure | None:
        if isinstance(exc, openai.APITimeoutError):
            return Failure(retry=True, detail="timed out", timed_out=True)
        if isinstance(exc, openai.APIConnectionError):
            return Failure(retry=True, detail=f"connection failed ({exc.__cause__ or exc})")
        if isinstance(exc, openai.APIStatusError):
            return Failure.http(exc.status_code, _server_message(exc),
                                retry_after_seconds(exc.response.headers))
        if isinstance(exc, openai.OpenAIError):
            return Failure(retry=False, detail=f"{type(exc).__name__}: {exc}")
        return None
