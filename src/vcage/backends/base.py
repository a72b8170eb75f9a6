"""Provider-neutral chat backend: messages, configuration, usage counter, registry. No MuJoCo import."""

from __future__ import annotations

import email.utils
import io
import math
import os
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, fields
from typing import Any, ClassVar, TypeVar
from urllib.parse import urlsplit

import numpy as np

from vcage.errors import BackendError, BackendTimeout, ConfigError, MissingAPIKeyError
from vcage.registry import Registry

ROLES = ("system", "user", "assistant")
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
LOCAL_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
T = TypeVar("T")
# provider -> (default base_url, default API key variable)
PROVIDERS = {"openai": ("http://localhost:8000/v1", "OPENAI_API_KEY"),
             "gemini": ("https://generativelanguage.googleapis.com", "GEMINI_API_KEY")}
LOCAL_PLACEHOLDER_KEY = "EMPTY"  # what vLLM / Ollama / LM Studio accept when they run without auth


def encode_png(image: bytes | np.ndarray) -> bytes:
    """PNG bytes of ``image``: PNG bytes are returned unchanged, a uint8 HxWx3 array is encoded."""
    if isinstance(image, (bytes, bytearray, memoryview)):
        data = bytes(image)
        if not data.startswith(PNG_SIGNATURE):
            raise ConfigError("image bytes must be a PNG file; encode other formats as PNG first")
        return data
    if isinstance(image, np.ndarray):
        if image.dtype != np.uint8 or image.ndim != 3 or image.shape[2] != 3 or 0 in image.shape:
            raise ConfigError(
                f"image array must be uint8 with shape (H, W, 3), got {image.dtype} {image.shape}"
            )
        from PIL import Image

        buf = io.BytesIO()
        Image.fromarray(np.ascontiguousarray(image)).save(buf, format="PNG")
        return buf.getvalue()
    raise ConfigError(f"image must be PNG bytes or a uint8 (H, W, 3) numpy array, got {type(image).__name__}")


@dataclass(frozen=True)
class Message:
    """One chat message; ``images`` (PNG bytes or uint8 HxWx3 arrays) are stored as PNG bytes."""

    role: str
    text: str
    images: tuple[bytes, ...] = ()

    def __init__(self, role: str, text: str, images: Sequence[bytes | np.ndarray] = ()) -> None:
        if role not in ROLES:
            raise ConfigError(f"message role {role!r} is invalid; use one of {list(ROLES)}")
        if not isinstance(text, str):
            raise ConfigError(f"message text must be a str, got {type(text).__name__}")
        if images and role != "user":
            raise ConfigError(f"images can only be attached to 'user' messages, not {role!r}")
        object.__setattr__(self, "role", role)
        object.__setattr__(self, "text", text)
        object.__setattr__(self, "images", tuple(encode_png(im) for im in images))


def _is_local(base_url: str) -> bool:
    return (urlsplit(base_url).hostname or "").lower() in LOCAL_HOSTS


@dataclass(frozen=True)
class BackendConfig:
    """Where and how to reach a chat model. The key itself is never serialised; see :meth:`to_dict`.

    ``api_key`` wins over the environment variable named by ``api_key_env``; local servers
    (localhost, 127.0.0.1, ::1) need neither. ``max_backoff`` caps every wait between retries,
    including waits a server asks for with ``Retry-After``.
    """

    base_url: str
    model: str
    provider: str = "openai"  # the registered backend that speaks to base_url: openai or gemini
    api_key: str | None = field(default=None, repr=False, compare=False)
    api_key_env: str = ""  # default: the provider's usual variable, OPENAI_API_KEY or GEMINI_API_KEY
    timeout: float = 30.0  # seconds per attempt
    max_retries: int = 3  # retries after the first attempt
    backoff: float = 0.5  # seconds; wait before retry n is backoff * 2**n
    max_backoff: float = 10.0  # seconds
    temperature: float = 0.0
    max_tokens: int | None = 1024

    def __post_init__(self) -> None:
        parts = urlsplit(self.base_url) if isinstance(self.base_url, str) else None
        if parts is None or parts.scheme not in ("http", "https") or not parts.hostname:
            raise ConfigError(
                f"base_url {self.base_url!r} must be an http(s) URL with a host, e.g. http://localhost:8000/v1"
            )
        if not isinstance(self.provider, str) or self.provider not in PROVIDERS:
            raise ConfigError(f"provider {self.provider!r} is unknown; use one of {sorted(PROVIDERS)}")
        if not isinstance(self.model, str) or not self.model.strip():
            raise ConfigError("model must be a non-empty model name as served by the endpoint")
        if not self.api_key_env:
            object.__setattr__(self, "api_key_env", PROVIDERS[self.provider][1])
        if not isinstance(self.api_key_env, str):
            raise ConfigError("api_key_env must name an environment variable, e.g. OPENAI_API_KEY")
        _check_number("timeout", self.timeout, low=0.0, strict=True)
        _check_number("backoff", self.backoff, low=0.0)
        _check_number("max_backoff", self.max_backoff, low=0.0)
        _check_number("temperature", self.temperature, low=0.0, high=2.0)
        retries = self.max_retries
        if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
            raise ConfigError(f"max_retries must be an integer >= 0, got {self.max_retries!r}")
        if self.max_tokens is not None and (
            isinstance(self.max_tokens, bool) or not isinstance(self.max_tokens, int) or self.max_tokens < 1
        ):
            raise ConfigError(f"max_tokens must be a positive integer or None, got {self.max_tokens!r}")

    @property
    def is_local(self) -> bool:
        """True when ``base_url`` points at this machine, where servers usually run without a key."""
        return _is_local(self.base_url)

    def resolve_api_key(self, environ: Mapping[str, str] | None = None) -> str:
        """The key to send: ``api_key``, else ``$api_key_env``, else a placeholder for local servers."""
        env = os.environ if environ is None else environ
        key = self.api_key or env.get(self.api_key_env)
        if key:
            return key
        if self.is_local:
            return LOCAL_PLACEHOLDER_KEY
        raise MissingAPIKeyError(
            f"no API key for {self.base_url}: set the environment variable {self.api_key_env} "
            f"(or point api_key_env at the variable that holds it), or pass api_key in the backend config"
        )

    def to_dict(self) -> dict[str, Any]:
        """Serialisable settings; the key is left out (only ``api_key_env`` is kept)."""
        data = asdict(self)
        data.pop("api_key")
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> BackendConfig:
        known = {f.name for f in fields(cls)}
        unknown = set(data) - known
        if unknown:
            raise ConfigError(f"unknown backend config keys {sorted(unknown)}; valid keys: {sorted(known)}")
        for required in ("base_url", "model"):
            if required not in data:
                raise ConfigError(f"backend config needs {required!r}")
        return cls(**dict(data))

    @classmethod
    def from_env(
        cls,
        prefix: str = "VCAGE_LLM",
        environ: Mapping[str, str] | None = None,
        **overrides: Any,
    ) -> BackendConfig:
        """Read ``{prefix}_PROVIDER``, ``{prefix}_BASE_URL``, ``{prefix}_MODEL`` and ``{prefix}_API_KEY``.

        ``VCAGE_LLM_PROVIDER`` is ``openai`` (default: any OpenAI-compatible server) or ``gemini``.
        ``VCAGE_LLM_BASE_URL`` defaults to the provider's usual address (``http://localhost:8000/v1``,
        vLLM's default, for openai; Google's API for gemini); ``VCAGE_LLM_MODEL`` is required. When
        ``VCAGE_LLM_API_KEY`` is set, ``api_key_env`` names it, so the key is read from the
        environment when a request is made and never stored in the config; otherwise the
        provider's usual variable is used (``OPENAI_API_KEY``, ``GEMINI_API_KEY``). ``overrides``
        set any other field.
        """
        env = os.environ if environ is None else environ
        provider = overrides.pop("provider", None) or env.get(f"{prefix}_PROVIDER") or "openai"
        if provider not in PROVIDERS:
            raise ConfigError(f"{prefix}_PROVIDER={provider!r} is unknown; use one of {sorted(PROVIDERS)}")
        base_url = env.get(f"{prefix}_BASE_URL") or PROVIDERS[provider][0]
        model = env.get(f"{prefix}_MODEL")
        if not model and "model" not in overrides:
            raise ConfigError(f"set {prefix}_MODEL to the model name served at {base_url}")
        data: dict[str, Any] = {"base_url": base_url, "model": model, "provider": provider}
        if env.get(f"{prefix}_API_KEY"):
            data["api_key_env"] = f"{prefix}_API_KEY"
        data.update(overrides)
        return cls.from_dict(data)


def _check_number(
    name: str, value: object, *, low: float, high: float = math.inf, strict: bool = False
) -> None:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok and isinstance(value, (int, float)):
        ok = (value > low if strict else value >= low) and value <= high
    if not ok:
        bound = f"> {low}" if strict else f">= {low}"
        upper = "" if high == math.inf else f" and <= {high}"
        raise ConfigError(f"{name} must be a finite number {bound}{upper}, got {value!r}")


@dataclass
class Usage:
    """Running totals of one backend: requests sent, retries, waits and tokens the server reported."""

    requests: int = 0
    retries: int = 0
    failures: int = 0
    wait_s: float = 0.0
    prompt_tokens: int = 0
    completion_tokens: int = 0

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


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
        cfg = self.config
        attempts = cfg.max_retries + 1
        for attempt in range(attempts):
            self._count(requests=1)
            try:
                return request()
            except Exception as exc:
                failure = self._failure(exc)
                if failure is None:
                    raise
                if not failure.retry or attempt + 1 == attempts:
                    self._count(failures=1)
                    raise self._error(failure, attempt + 1) from exc
            backoff = cfg.backoff * 2**attempt if failure.wait is None else failure.wait
            wait = min(cfg.max_backoff, backoff)
            self._count(retries=1, wait_s=wait)
            time.sleep(wait)
        raise AssertionError("unreachable")  # pragma: no cover

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


BackendFactory = Callable[[BackendConfig], ChatBackend]
BACKENDS: Registry[BackendFactory] = Registry("backend")


def make_backend(name: str, config: BackendConfig) -> ChatBackend:
    """Build the backend registered as ``name``; unknown names list the valid ones."""
    return BACKENDS.get(name)(config)


def connect(config: BackendConfig) -> ChatBackend:
    """Build the backend for ``config.provider``."""
    return make_backend(config.provider, config)
