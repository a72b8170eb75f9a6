"""The provider-neutral chat backend every provider implements. No MuJoCo import."""

from __future__ import annotations

import threading
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

from vcage.backends.retry import CircuitBreaker, Failure, call_with_retries
from vcage.backends.usage import Usage
from vcage.errors import BackendError, BackendUnavailableError, BackendUnavailableTimeout, EmptyReplyError

if TYPE_CHECKING:
    from vcage.backends.config import BackendConfig
    from vcage.backends.messages import Message

T = TypeVar("T")
MAX_LISTED = 20  # served models named in a preflight error


class ChatBackend(ABC):
    """Sends chat messages to a model and returns the reply text.

    Subclasses make one request in :meth:`chat` through :meth:`_send`, which retries what
    :meth:`_failure` says is worth retrying (timeouts, connection errors, 429, 5xx) with exponential
    backoff or the server's requested wait, capped by ``max_backoff``, and counts it all in ``usage``.

    A request that still fails raises :class:`BackendUnavailableError` when the endpoint could not
    be reached or will not answer (timeouts, connection errors, 429/5xx, 401/403/404), otherwise a
    plain :class:`BackendError` (e.g. 400: the server refused this request). After
    ``config.breaker_failures`` failed requests in a row the circuit opens: :meth:`chat` then raises
    :class:`BackendUnavailableError` at once, without touching the network, until :meth:`reset`.
    :meth:`preflight` checks the endpoint and the model with one cheap request before any work.
    """

    name: ClassVar[str] = "base"
    not_found_hint: ClassVar[str] = "check base_url and the model name"

    def __init__(self, config: BackendConfig) -> None:
        self.config = config
        self.usage = Usage()
        self._usage_lock = threading.Lock()
        self.breaker = CircuitBreaker(config.breaker_failures)

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

    def reset(self) -> None:
        """Close the circuit breaker: the next :meth:`chat` is sent again."""
        self.breaker.reset()

    def preflight(self) -> None:
        """Check with one cheap real request that the endpoint answers and serves ``config.model``.

        One attempt with the configured timeout and no retries; the circuit breaker is neither
        consulted nor changed. Raises :class:`BackendUnavailableError` naming the URL, the model and
        the cause (connection refused, timeout, HTTP status and the server's message, or the models
        the server does serve). Providers without a probe (see :meth:`_probe`) check nothing.
        """
        if type(self)._probe is ChatBackend._probe or not self.config.preflight:
            return  # this provider has no probe, or the config says not to: nothing is sent, nothing checked
        cfg = self.config
        url = self.probe_url
        self._count(requests=1)
        try:
            served = self._probe()
        except Exception as exc:
            failure = self._failure(exc)
            if failure is None:
                raise
            self._count(failures=1)
            error = self._error(failure, 1, what="preflight request", url=url)
            if isinstance(error, BackendUnavailableError):
                raise error from exc
            raise BackendUnavailableError(str(error), endpoint=url, model=cfg.model,
                                          status=error.status) from exc
        if served and not self._serves(served):
            shown = ", ".join(served[:MAX_LISTED]) + (
                f" and {len(served) - MAX_LISTED} more" if len(served) > MAX_LISTED else "")
            raise BackendUnavailableError(
                f"model {cfg.model!r} is not served at {cfg.base_url}; served: {shown}. Set the "
                "backend's model to one of these, or point base_url at the server that has it",
                endpoint=url, model=cfg.model, status=404)

    @property
    def probe_url(self) -> str:
        """The URL :meth:`preflight` requests; the default is the chat endpoint."""
        return self.endpoint

    def _probe(self) -> list[str] | None:
        """Make the preflight request: the model names the server lists, or None if it lists none.

        Raise what the SDK raises (classified by :meth:`_failure`) when the request fails. The
        default sends nothing and checks nothing; providers override it with their cheapest call.
        """
        return None

    def _serves(self, served: Sequence[str]) -> bool:
        model = self.config.model
        return model in served or (":" not in model and f"{model}:latest" in served)  # Ollama's tags

    def _send(self, request: Callable[[], T], *, what: str = "chat request", url: str | None = None) -> T:
        """``request()`` with retries, behind the circuit breaker; ``what`` and ``url`` name the
        request in errors (default: a chat request to :attr:`endpoint`)."""
        opened_by = self.breaker.check()
        if opened_by is not None:
            cfg = self.config
            raise BackendUnavailableError(
                f"circuit open after {self.breaker.limit} consecutive failures: {opened_by} "
                f"(no request sent; fix the endpoint, then call reset() on the backend)",
                endpoint=self.endpoint, model=cfg.model, status=getattr(opened_by, "status", None))
        try:
            result = call_with_retries(request, self.config, classify=self._failure,
                                       give_up=lambda f, n: self._error(f, n, what=what, url=url),
                                       count=self._count)
        except BackendError as exc:
            self.breaker.failure(exc)
            raise
        self.breaker.success()
        return result

    def _error(self, failure: Failure, attempts: int, *, what: str = "chat request",
               url: str | None = None) -> BackendError:
        cfg = self.config
        url = url or self.endpoint
        tries = f"after {attempts} attempt{'s' if attempts != 1 else ''}"
        where = f"{what} to {url} (model {cfg.model!r})"
        if failure.timed_out:
            return BackendUnavailableTimeout(
                f"{where} timed out {tries} (timeout {cfg.timeout} s each); raise timeout or max_retries, "
                f"or check the server at {cfg.base_url} is not overloaded",
                endpoint=url, model=cfg.model,
            )
        detail = failure.detail if failure.status is None else f"HTTP {failure.status}: {failure.detail}"
        kind = BackendUnavailableError if failure.unavailable else BackendError
        return kind(f"{where} failed {tries}: {detail}; {self._hint(failure.status)}",
                    endpoint=url, model=cfg.model, status=failure.status)

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
        raise EmptyReplyError(
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
