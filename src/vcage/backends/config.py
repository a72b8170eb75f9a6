"""Where and how to reach a chat model, checked when built so a bad value fails before any request."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from typing import Any
from urllib.parse import urlsplit

from vcage.backends.providers import PROVIDERS
from vcage.errors import ConfigError, MissingAPIKeyError

LOCAL_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
LOCAL_PLACEHOLDER_KEY = "EMPTY"  # what vLLM / Ollama / LM Studio accept when they run without auth


def _is_local(base_url: str) -> bool:
    return (urlsplit(base_url).hostname or "").lower() in LOCAL_HOSTS


@dataclass(frozen=True)
class BackendConfig:
    """Where and how to reach a chat model. The key itself is never serialised; see :meth:`to_dict`.

    ``api_key`` wins over the environment variable named by ``api_key_env``; local servers
    (localhost, 127.0.0.1, ::1) need neither. ``max_backoff`` caps every wait between retries,
    including waits a server asks for with ``Retry-After``. One request therefore takes at most
    ``timeout * (1 + max_retries)`` seconds plus the waits (each ``min(max_backoff, backoff * 2**n)``,
    or the server's ``Retry-After`` capped by ``max_backoff``). After ``breaker_failures`` requests
    in a row have failed that way, the backend's circuit opens and further requests fail at once
    with :class:`~vcage.errors.BackendUnavailableError` until ``reset()``.
    """

    base_url: str
    model: str
    provider: str = "openai"  # a registered provider that speaks to base_url: openai or gemini built in
    api_key: str | None = field(default=None, repr=False, compare=False)
    api_key_env: str = ""  # default: the provider's usual variable, OPENAI_API_KEY or GEMINI_API_KEY
    timeout: float = 30.0  # seconds per attempt
    max_retries: int = 3  # retries after the first attempt
    backoff: float = 0.5  # seconds; wait before retry n is backoff * 2**n
    max_backoff: float = 10.0  # seconds
    breaker_failures: int = 3  # failed requests in a row (after their retries) that open the circuit
    temperature: float = 0.0
    max_tokens: int | None = 1024
    # ask the endpoint before any work whether it answers and serves the model (``GET /models`` for
    # OpenAI-compatible servers); off for servers that do not list their models
    preflight: bool = True

    def __post_init__(self) -> None:
        parts = urlsplit(self.base_url) if isinstance(self.base_url, str) else None
        if parts is None or parts.scheme not in ("http", "https") or not parts.hostname:
            raise ConfigError(
                f"base_url {self.base_url!r} must be an http(s) URL with a host, e.g. http://localhost:8000/v1"
            )
        if not isinstance(self.provider, str) or self.provider not in PROVIDERS:
            raise ConfigError(f"provider {self.provider!r} is unknown; use one of {PROVIDERS.names()}")
        if not isinstance(self.model, str) or not self.model.strip():
            raise ConfigError("model must be a non-empty model name as served by the endpoint")
        if not self.api_key_env:
            object.__setattr__(self, "api_key_env", PROVIDERS.get(self.provider).api_key_env)
        if not isinstance(self.api_key_env, str):
            raise ConfigError("api_key_env must name an environment variable, e.g. OPENAI_API_KEY")
        _check_number("timeout", self.timeout, low=0.0, strict=True)
        _check_number("backoff", self.backoff, low=0.0)
        _check_number("max_backoff", self.max_backoff, low=0.0)
        _check_number("temperature", self.temperature, low=0.0, high=2.0)
        retries = self.max_retries
        if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
            raise ConfigError(f"max_retries must be an integer >= 0, got {self.max_retries!r}")
        breaker = self.breaker_failures
        if isinstance(breaker, bool) or not isinstance(breaker, int) or breaker < 1:
            raise ConfigError(f"breaker_failures must be an integer >= 1, got {self.breaker_failures!r}")
        if not isinstance(self.preflight, bool):
            raise ConfigError(f"preflight must be true or false, got {self.preflight!r}")
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
        provider's usual variable is used (``OPENAI_API_KEY``, ``GEMINI_API_KEY``).
        ``VCAGE_LLM_PREFLIGHT=0`` skips the check before any work (for servers that list no models).
        ``overrides`` set any other field. The defaults are the ones the provider was registered with.
        """
        env = os.environ if environ is None else environ
        provider = overrides.pop("provider", None) or env.get(f"{prefix}_PROVIDER") or "openai"
        if provider not in PROVIDERS:
            raise ConfigError(f"{prefix}_PROVIDER={provider!r} is unknown; use one of {PROVIDERS.names()}")
        base_url = env.get(f"{prefix}_BASE_URL") or PROVIDERS.get(provider).base_url
        model = env.get(f"{prefix}_MODEL")
        if not model and "model" not in overrides:
            raise ConfigError(f"set {prefix}_MODEL to the model name served at {base_url}")
        data: dict[str, Any] = {"base_url": base_url, "model": model, "provider": provider}
        if env.get(f"{prefix}_API_KEY"):
            data["api_key_env"] = f"{prefix}_API_KEY"
        flag = env.get(f"{prefix}_PREFLIGHT", "").strip().lower()
        if flag:
            if flag not in ("0", "1", "true", "false", "yes", "no"):
                raise ConfigError(f"{prefix}_PREFLIGHT={flag!r}: use 0 (skip the check of the endpoint "
                                  "before any work) or 1")
            data["preflight"] = flag in ("1", "true", "yes")
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
