"""The provider registry is the one table: config validation, env defaults and connect all read it."""

from __future__ import annotations

import subprocess
import sys
import uuid
from collections.abc import Sequence

import pytest

from vcage.backends import (
    BACKENDS,
    PROVIDERS,
    BackendConfig,
    ChatBackend,
    Failure,
    Message,
    Provider,
    add_provider,
    connect,
)
from vcage.errors import ConfigError, RegistryError


class Canned(ChatBackend):
    """Answers every chat with the same text, without a server."""

    name = "canned"

    @property
    def endpoint(self) -> str:
        return self.config.base_url

    def chat(self, messages: Sequence[Message], *, json_mode: bool = False) -> str:
        return self._send(lambda: "canned reply")

    def _failure(self, exc: Exception) -> Failure | None:
        return None


def test_one_registration_makes_config_env_defaults_and_connect_work() -> None:
    name = f"canned-{uuid.uuid4().hex[:8]}"  # fresh: the registry has no removal, so never reuse a name
    with pytest.raises(ConfigError, match="is unknown"):
        BackendConfig(base_url="http://localhost:9/v1", model="m", provider=name)

    add_provider(Provider(name, base_url="https://canned.example.com/api", api_key_env="CANNED_KEY",
                          factory=Canned))

    assert name in PROVIDERS and name in BACKENDS and BACKENDS.get(name) is Canned
    cfg = BackendConfig.from_env("VCAGE_TEST", environ={"VCAGE_TEST_PROVIDER": name, "VCAGE_TEST_MODEL": "m"})
    assert (cfg.provider, cfg.base_url) == (name, "https://canned.example.com/api")
    assert cfg.api_key_env == "CANNED_KEY"
    with connect(cfg) as backend:
        assert isinstance(backend, Canned) and backend.chat([Message("user", "hi")]) == "canned reply"
        assert backend.usage.requests == 1
        backend.preflight()  # a provider without a probe has nothing to check and sends nothing
        assert backend.usage.requests == 1
    with pytest.raises(RegistryError, match="already registered"):
        add_provider(Provider(name, base_url="http://localhost:1", api_key_env="X", factory=Canned))


def test_builtin_providers_come_from_the_registry() -> None:
    assert BACKENDS.names() == PROVIDERS.names() and {"openai", "gemini"} <= set(BACKENDS)
    openai = PROVIDERS.get("openai")
    cfg = BackendConfig.from_env(environ={"VCAGE_LLM_MODEL": "m"})
    assert (cfg.base_url, cfg.api_key_env) == (openai.base_url, openai.api_key_env)


def test_backends_import_only_vcage_core() -> None:
    code = ("import sys, vcage; before = set(sys.modules); import vcage.backends; "
            "extra = sorted(m for m in set(sys.modules) - before if m.startswith('vcage.') and "
            "not m.startswith(('vcage.backends', 'vcage.errors', 'vcage.registry'))); "
            "assert not extra, extra")
    subprocess.run([sys.executable, "-c", code], check=True)
