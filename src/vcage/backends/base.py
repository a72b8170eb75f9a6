"""The provider-neutral chat backend every provider implements. No MuJoCo import."""

from __future__ import annotations

import threading
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

from vcage.backends.retry import Failure, call_with_retries
from vcage.backends.usage import Usage
from vcage.errors import BackendError, BackendTimeout

if TYPE_CHECKING:
    from vcage.backends.config import BackendConfig
    from vcage.backends.messages import Message

T = TypeVar("T")


class ChatBackend(ABC):
    """Sends chat messages to a model and returns the reply text.

    Subclasses make one request in :meth:`chat` through :meth:`_send`, which retries what
    :meth:`_failure` says is worth retrying (timeouts, connection errors, 429, 5xx) with exponential
    backoff or the server's requested wait, capped by ``max_backoff``, and counts it all in ``usage``.
    """

    name: ClassVar[str] = "base"
    not_found_hint: ClassVar[str] = "check base_url and the model name"

    def __init__(self, config: BackendConfig) -> None:
        self.config = config
        self.usage = Usage()
        self._usage_lock = threading.Lock()

    @property
    @abstractmethod
    def endpoint(self) -> str:
        """The URL chat requests go to, for messages and errors."""

    @abstractmethod
    def chat(self, messages: Sequence[Message], *, json_mode: bool = False) -> str:
        """The model's reply to ``messages``; ``json_mode`` asks the server for a JSON object."""

    @abstractmethod
    def _failure(self, exc: Exception) -> Failure | None:
        """How to handle ``exc`` raised by a request; None for errors that are not the transport's."""

    def close(self) -> None:
        """Release connections; the default has nothing to release."""

    def _send(self, request: Callable[[], T]) -> T:
        return call_with_retries(request, self.config, classify=self._failure, give_up=self._error,
                                 count=self._count)

    def _error(self, failure: Failure, attempts: int) -> BackendError:
        cfg = self.config
        tries = f"after {attempts} attempt{'s' if attempts != 1 else ''}"
        where = f"chat request to {self.endpoint} (model {cfg.model!r})"
        if failure.timed_out:
            return BackendTimeout(
                f"{where} timed out {tries} (timeout {cfg.timeout} s each); raise timeout or max_retries, "
                f"or check the server at {cfg.base_url} is not overloaded",
                endpoint=self.endpoint, model=cfg.model,
            )
        detail = failure.detail if failure.status is None else f"HTTP {failure.status}: {failure.detail}"
        return BackendError(f"{where} failed {tries}: {detail}; {self._hint(failure.status)}",
                            endpoint=self.endpoint, model=cfg.model, status=failure.status)

    def _hint(self, status: int | None) -> str:
        cfg = self.config
        if status in (401, 403):
            return f"check the API key in ${cfg.api_key_env} (or api_key) is valid for this endpoint"
        if status == 404:
            return self.not_found_hint
        if status == 429:
            return "the server is rate limiting: lower concurrency or raise max_retries/backoff"
        if status is not None and status >= 500:
            return "the server failed: check its logs and that the model is loaded"
        if status is not None:
            return ("the server rejected the request: check the model supports these messages, images "
                    "and json_mode")
        return f"check the server is running and reachable at {cfg.base_url}"

    def _reply(self, response: Any, text: str | None, prompt_tokens: int, completion_tokens: int) -> str:
        """Count the tokens a response reports and return its text; no text is an error."""
        self._count(prompt_tokens=prompt_tokens, completion_tokens=completion_tokens)
        if isinstance(text, str) and text:
            return text
        cfg = self.config
        raise BackendError(
            f"chat request to {self.endpoint} (model {cfg.model!r}) returned no message content "
            f"(response: {str(response)[:300]}); check the model produces text for this prompt",
            endpoint=self.endpoint, model=cfg.model, status=200,
        )

    def _count(self, **increments: float) -> None:
        with self._usage_lock:
            for key, value in increments.items():
                setattr(self.usage, key, getattr(self.usage, key) + value)

    def __enter__(self) -> ChatBackend:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
