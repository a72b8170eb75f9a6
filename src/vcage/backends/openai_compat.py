"""Chat backend for any OpenAI-compatible endpoint (vLLM, Ollama, LM Studio, hosted APIs).

Retries are done here, not by the SDK, so they are counted and bounded: timeouts, connection errors,
429 and 5xx are retried with exponential backoff (or the server's ``Retry-After``), capped by
``max_backoff``; other 4xx fail at once.
"""

from __future__ import annotations

import base64
import email.utils
import time
from collections.abc import Sequence
from typing import Any

import openai

from vcage.backends.base import BACKENDS, BackendConfig, ChatBackend, Message
from vcage.errors import BackendError, BackendTimeout


def message_payload(message: Message) -> dict[str, Any]:
    """The chat-completions form of ``message``; images become base64 PNG ``image_url`` parts."""
    if not message.images:
        return {"role": message.role, "content": message.text}
    parts: list[dict[str, Any]] = [{"type": "text", "text": message.text}] if message.text else []
    for png in message.images:
        url = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
        parts.append({"type": "image_url", "image_url": {"url": url}})
    return {"role": message.role, "content": parts}


def retry_after_seconds(headers: Any) -> float | None:
    """Seconds a server asked to wait (``retry-after-ms`` or ``Retry-After``), or None."""
    try:
        millis = headers.get("retry-after-ms")
        if millis is not None:
            return max(0.0, float(millis) / 1000.0)
        value = headers.get("retry-after")
    except (AttributeError, ValueError):
        return None
    if value is None:
        return None
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - time.time())


def _server_message(exc: openai.APIStatusError) -> str:
    body = exc.body
    if isinstance(body, dict) and isinstance(body.get("message"), str):
        return body["message"]
    if isinstance(body, str) and body.strip():
        return body.strip()[:500]
    return exc.message


def _hint(status: int | None, config: BackendConfig) -> str:
    if status in (401, 403):
        return f"check the API key in ${config.api_key_env} (or api_key) is valid for this endpoint"
    if status == 404:
        return "check base_url (OpenAI-compatible servers usually end in /v1) and the model name"
    if status == 429:
        return "the server is rate limiting: lower concurrency or raise max_retries/backoff"
    if status is not None and status >= 500:
        return "the server failed: check its logs and that the model is loaded"
    if status is not None:
        return "the server rejected the request: check the model supports these messages, images, json_mode"
    return f"check the server is running and reachable at {config.base_url}"


@BACKENDS.register("openai")
class OpenAIChatBackend(ChatBackend):
    """Chat completions through the ``openai`` SDK against ``config.base_url``."""

    name = "openai"

    def __init__(self, config: BackendConfig) -> None:
        super().__init__()
        self.config = config
        self._client = openai.OpenAI(
            base_url=config.base_url,
            api_key=config.resolve_api_key(),  # raises MissingAPIKeyError before any request
            timeout=config.timeout,
            max_retries=0,
        )

    def close(self) -> None:
        self._client.close()

    def chat(self, messages: Sequence[Message], *, json_mode: bool = False) -> str:
        if not messages:
            raise BackendError("chat needs at least one message", endpoint=self.config.endpoint,
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
        return self._reply_text(self._create(request))

    def _create(self, request: dict[str, Any]) -> Any:
        cfg = self.config
        attempts = cfg.max_retries + 1
        for attempt in range(attempts):
            self._count(requests=1)
            try:
                return self._client.chat.completions.create(**request)
            except openai.APITimeoutError as exc:
                failure: Exception = exc
                status, wait_hint = None, None
            except openai.APIConnectionError as exc:
                failure, status, wait_hint = exc, None, None
            except openai.APIStatusError as exc:
                failure, status = exc, exc.status_code
                if status != 429 and status < 500:  # other client errors will not improve by retrying
                    self._count(failures=1)
                    raise self._error(exc, status, attempt + 1) from exc
                wait_hint = retry_after_seconds(exc.response.headers)
            except openai.OpenAIError as exc:
                self._count(failures=1)
                raise self._error(exc, None, attempt + 1) from exc
            if attempt + 1 == attempts:
                self._count(failures=1)
                raise self._error(failure, status, attempts) from failure
            wait = min(cfg.max_backoff, cfg.backoff * 2**attempt if wait_hint is None else wait_hint)
            self._count(retries=1, wait_s=wait)
            time.sleep(wait)
        raise AssertionError("unreachable")  # pragma: no cover

    def _error(self, exc: Exception, status: int | None, attempts: int) -> BackendError:
        cfg = self.config
        tries = f"after {attempts} attempt{'s' if attempts != 1 else ''}"
        where = f"chat request to {cfg.endpoint} (model {cfg.model!r})"
        if isinstance(exc, openai.APITimeoutError):
            return BackendTimeout(
                f"{where} timed out {tries} (timeout {cfg.timeout} s each); raise timeout or max_retries, "
                f"or check the server at {cfg.base_url} is not overloaded",
                endpoint=cfg.endpoint, model=cfg.model,
            )
        if isinstance(exc, openai.APIStatusError):
            detail = f"HTTP {status}: {_server_message(exc)}"
        elif isinstance(exc, openai.APIConnectionError):
            detail = f"connection failed ({exc.__cause__ or exc})"
        else:
            detail = f"{type(exc).__name__}: {exc}"
        return BackendError(f"{where} failed {tries}: {detail}; {_hint(status, cfg)}",
                            endpoint=cfg.endpoint, model=cfg.model, status=status)

    def _reply_text(self, response: Any) -> str:
        usage = getattr(response, "usage", None)
        if usage is not None:
            self._count(prompt_tokens=usage.prompt_tokens or 0,
                        completion_tokens=usage.completion_tokens or 0)
        choices = getattr(response, "choices", None)
        content = choices[0].message.content if choices else None
        if not isinstance(content, str) or not content:
            cfg = self.config
            raise BackendError(
                f"chat request to {cfg.endpoint} (model {cfg.model!r}) returned no message content "
                f"(response: {str(response)[:300]}); check the model produces text for this prompt",
                endpoint=cfg.endpoint, model=cfg.model, status=200,
            )
        return content
