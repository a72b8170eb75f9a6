"""Chat backend for Google's Gemini API (``generateContent``) through the ``google-genai`` SDK.

System messages become the request's system instruction, assistant messages the ``model`` role,
and images inline PNG parts. As for the OpenAI-compatible backend, retries are done by
:class:`ChatBackend` (the SDK's own are switched off): timeouts, connection errors, 429 and 5xx are
retried with backoff or the wait the server asks for (``Retry-After`` or the error's ``RetryInfo``).
``preflight`` asks ``models.get`` for the configured model (and, if it is not found, which are).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import httpx2
from google import genai
from google.genai import errors, types

from vcage.backends.base import ChatBackend
from vcage.backends.config import BackendConfig
from vcage.backends.messages import Message
from vcage.backends.retry import Failure, retry_after_seconds
from vcage.errors import BackendError

API_VERSION = "v1beta"
ROLE = {"user": "user", "assistant": "model"}


def contents(messages: Sequence[Message]) -> tuple[str | None, list[types.Content]]:
    """The system instruction (system messages joined) and the conversation in Gemini's form."""
    system = "\n\n".join(m.text for m in messages if m.role == "system") or None
    turns = []
    for m in messages:
        if m.role == "system":
            continue
        parts = [types.Part.from_text(text=m.text)] if m.text else []
        parts += [types.Part.from_bytes(data=png, mime_type="image/png") for png in m.images]
        turns.append(types.Content(role=ROLE[m.role], parts=parts))
    return system, turns


def retry_delay_seconds(details: Any) -> float | None:
    """The wait a Gemini error asks for in its ``google.rpc.RetryInfo`` detail (e.g. ``"13s"``)."""
    error = details.get("error", details) if isinstance(details, dict) else None
    for item in (error or {}).get("details") or []:
        if isinstance(item, dict) and str(item.get("@type", "")).endswith("RetryInfo"):
            match = re.fullmatch(r"\s*([0-9.]+)s\s*", str(item.get("retryDelay", "")))
            if match:
                return float(match.group(1))
    return None


class GeminiChatBackend(ChatBackend):
    """``models.generate_content`` through ``google-genai`` against ``config.base_url``.

Registered as ``gemini`` in :mod:`vcage.backends.builtin`, whose factory imports this module only when
it is used.
"""

    name = "gemini"
    not_found_hint = "check the model name (e.g. gemini-2.5-flash) and base_url"

    def __init__(self, config: BackendConfig) -> None:
        super().__init__(config)
        options = types.HttpOptions(base_url=config.base_url, api_version=API_VERSION,
                                    timeout=max(1, round(config.timeout * 1000)),
                                    retry_options=types.HttpRetryOptions(attempts=1))
        self._client = genai.Client(api_key=config.resolve_api_key(), http_options=options)

    @property
    def endpoint(self) -> str:
        return f"{self.config.base_url.rstrip('/')}/{API_VERSION}/models/{self.config.model}:generateContent"

    @property
    def probe_url(self) -> str:
        return f"{self.config.base_url.rstrip('/')}/{API_VERSION}/models/{self.config.model}"

    def close(self) -> None:
        self._client.close()

    def _probe(self) -> list[str] | None:
        """``models.get(model)``; if the model is not found, the names the server lists instead."""
        try:
            self._client.models.get(model=self.config.model)
        except errors.APIError as exc:
            if exc.code != 404:
                raise
            try:
                listed = self._client.models.list(config={"page_size": 100}).page
            except (errors.APIError, httpx2.HTTPError):
                raise exc from None
            served = [m.name.removeprefix("models/") for m in listed if m.name]
            if not served or self._serves(served):
                raise  # the listing does not explain the 404: report it as it is
            return served
        return None

    def chat(self, messages: Sequence[Message], *, json_mode: bool = False) -> str:
        system, turns = contents(messages)
        if not turns:
            raise BackendError("chat needs at least one user or assistant message",
                               endpoint=self.endpoint, model=self.config.model)
        cfg = self.config
        generation = types.GenerateContentConfig(
            system_instruction=system, temperature=cfg.temperature, max_output_tokens=cfg.max_tokens,
            response_mime_type="application/json" if json_mode else None,
        )
        response = self._send(lambda: self._client.models.generate_content(
            model=cfg.model, contents=turns, config=generation))
        usage = response.usage_metadata
        candidates = response.candidates or []
        content = candidates[0].content if candidates else None
        text = "".join(p.text or "" for p in (content.parts or [])) if content is not None else ""
        return self._reply(response, text, getattr(usage, "prompt_token_count", 0) or 0,
                           getattr(usage, "candidates_token_count", 0) or 0)

    def _failure(self, exc: Exception) -> Failure | None:
        if isinstance(exc, httpx2.TimeoutException):
            return Failure(retry=True, detail="timed out", timed_out=True)
        if isinstance(exc, httpx2.TransportError):
            return Failure(retry=True, detail=f"connection failed ({exc})")
        if isinstance(exc, errors.APIError):
            headers = getattr(exc.response, "headers", None)
            wait = retry_after_seconds(headers) if headers is not None else None
            return Failure.http(exc.code, str(exc.message or exc),
                                wait if wait is not None else retry_delay_seconds(exc.details))
        return None
