"""When a failed request is worth another try, how long to wait first, and when to stop trying.

Backends retry here rather than in their SDKs so every provider's retries are counted, bounded by
``max_retries`` and capped by ``max_backoff`` the same way, including waits a server asks for. The
:class:`CircuitBreaker` stops sending once ``breaker_failures`` requests in a row have failed.
"""

from __future__ import annotations

import email.utils
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

if TYPE_CHECKING:
    from vcage.backends.config import BackendConfig

T = TypeVar("T")


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


@dataclass(frozen=True)
class Failure:
    """How a failed request is handled: whether to retry, its HTTP status, what went wrong."""

    retry: bool
    detail: str
    status: int | None = None
    wait: float | None = None  # seconds the server asked to wait before retrying
    timed_out: bool = False

    @classmethod
    def http(cls, status: int, detail: str, wait: float | None = None) -> Failure:
        """An HTTP error: 429 and 5xx are retried; other statuses will not improve by retrying."""
        return cls(retry=status == 429 or status >= 500, detail=detail, status=status, wait=wait)

    @property
    def unavailable(self) -> bool:
        """Whether the endpoint could not be reached or will not answer (an outage, not a reply).

        Timeouts, connection errors, 429 and 5xx (once retries are spent), and 401, 403 and 404,
        which no retry fixes: wrong key, wrong URL or a model the server does not have.
        """
        if self.timed_out:
            return True
        if self.status is None:
            return self.retry  # a connection error; other errors without a status are the client's
        return self.status in UNAVAILABLE_STATUSES or self.status >= 500


UNAVAILABLE_STATUSES = frozenset({401, 403, 404, 429})


class CircuitBreaker:
    """Opens after ``limit`` consecutive failed requests and stays open until :meth:`reset`.

    A request that succeeds resets the count. While open, :meth:`check` returns the failure that
    opened it, so callers fail at once instead of waiting for timeouts again. Thread-safe.
    """

    def __init__(self, limit: int) -> None:
        self.limit = limit
        self._lock = threading.Lock()
        self._failures = 0
        self._last: Exception | None = None

    @property
    def failures(self) -> int:
        """Failed requests in a row so far."""
        with self._lock:
            return self._failures

    @property
    def is_open(self) -> bool:
        with self._lock:
            return self._failures >= self.limit

    def check(self) -> Exception | None:
        """The last failure while the circuit is open, else None (requests may be sent)."""
        with self._lock:
            return self._last if self._failures >= self.limit else None

    def success(self) -> None:
        with self._lock:
            if self._failures < self.limit:  # an answer that was in flight does not close an open circuit
                self._failures = 0
                self._last = None

    def failure(self, error: Exception) -> None:
        with self._lock:
            self._failures += 1
            self._last = error

    def reset(self) -> None:
        """Close the circuit: the next request is sent."""
        with self._lock:
            self._failures = 0
            self._last = None


def call_with_retries(
    request: Callable[[], T],
    config: BackendConfig,
    *,
    classify: Callable[[Exception], Failure | None],
    give_up: Callable[[Failure, int], Exception],
    count: Callable[..., None],
) -> T:
    """``request()``, retried while ``classify`` says its error is worth retrying.

    An error ``classify`` maps to None is not the transport's and propagates untouched; the last
    failure, or one not worth retrying, raises ``give_up(failure, attempts)``. The wait before retry
    n is ``backoff * 2**n`` or what the server asked for, capped by ``max_backoff``; requests,
    retries, failures and waits are reported to ``count``.
    """
    attempts = config.max_retries + 1
    for attempt in range(attempts):
        count(requests=1)
        try:
            return request()
        except Exception as exc:
            failure = classify(exc)
            if failure is None:
                raise
            if not failure.retry or attempt + 1 == attempts:
                count(failures=1)
                raise give_up(failure, attempt + 1) from exc
        backoff = config.backoff * 2**attempt if failure.wait is None else failure.wait
        wait = min(config.max_backoff, backoff)
        count(retries=1, wait_s=wait)
        time.sleep(wait)
    raise AssertionError("unreachable")  # pragma: no cover
