"""The one registry of model providers: each name with its default address, key variable and factory.

:class:`BackendConfig` validates ``provider`` and :meth:`BackendConfig.from_env` takes its defaults
from here, and :func:`connect` builds from here, so a provider is added by one :func:`add_provider`
and the three cannot disagree. This module imports nothing else of ``vcage.backends`` at run time:
``config`` imports it to validate, and the modules that register providers import it too.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vcage.registry import Registry

if TYPE_CHECKING:
    from vcage.backends.base import ChatBackend
    from vcage.backends.config import BackendConfig

BackendFactory = Callable[["BackendConfig"], "ChatBackend"]


@dataclass(frozen=True)
class Provider:
    """A registered provider. ``factory`` may import its SDK when first called, so that importing
    ``vcage.backends`` stays cheap for providers a run never uses."""

    name: str
    base_url: str  # where BackendConfig.from_env points when {prefix}_BASE_URL is unset
    api_key_env: str  # the variable the provider's key usually lives in, e.g. OPENAI_API_KEY
    factory: BackendFactory


PROVIDERS: Registry[Provider] = Registry("backend")


def add_provider(provider: Provider) -> Provider:
    """Register ``provider`` under its name; a name registered twice raises."""
    return PROVIDERS.add(provider.name, provider)


class BackendFactories:
    """:data:`PROVIDERS` seen as name -> factory, read-only: what ``BACKENDS`` has always offered.

    It is a view, not a second table, so it lists exactly the registered providers; register new
    ones with :func:`add_provider`, which also gives them the defaults a config needs.
    """

    def get(self, name: str) -> BackendFactory:
        return PROVIDERS.get(name).factory

    def names(self) -> list[str]:
        return PROVIDERS.names()

    def values(self) -> list[BackendFactory]:
        """The factories, in name order."""
        return [p.factory for p in PROVIDERS.values()]

    def __contains__(self, name: object) -> bool:
        return name in PROVIDERS

    def __iter__(self) -> Iterator[str]:
        return iter(PROVIDERS)

    def __len__(self) -> int:
        return len(PROVIDERS)


BACKENDS = BackendFactories()


def make_backend(name: str, config: BackendConfig) -> ChatBackend:
    """Build the backend registered as ``name``; unknown names list the valid ones."""
    return BACKENDS.get(name)(config)


def connect(config: BackendConfig) -> ChatBackend:
    """Build the backend for ``config.provider``."""
    return make_backend(config.provider, config)
