"""Provider transport for LLM planners and VLM critics. Depends on vcage core only: no MuJoCo import.

``connect(BackendConfig(...))`` builds the :class:`ChatBackend` registered for the config's provider
(``openai``: any OpenAI-compatible server; ``gemini``: Google's Gemini API); ``BackendConfig.from_env``
reads the ``VCAGE_LLM_*`` / ``VCAGE_VLM_*`` variables.

Modules: ``messages`` (Message, PNG encoding), ``config`` (BackendConfig), ``usage`` (Usage),
``retry`` (Failure, Retry-After, the retry loop, the circuit breaker), ``base`` (ChatBackend: chat,
preflight, reset), ``providers`` (the one
provider registry, ``connect``), ``builtin`` (registers openai and gemini), and one module per
provider's SDK (``openai_compat``, ``gemini``). Image editing: ``images`` (ImageEditBackend,
ImageAnswer, ``connect_images``) with ``gemini_images`` (``generateContent``) and ``openai_images``
(any OpenAI-compatible ``/images/edits``), imported when first used.
"""

from vcage.backends import builtin  # noqa: F401  registers the built-in providers
from vcage.backends.base import ChatBackend
from vcage.backends.config import BackendConfig
from vcage.backends.messages import Message, encode_png
from vcage.backends.openai_compat import OpenAIChatBackend
from vcage.backends.providers import (
    BACKENDS,
    PROVIDERS,
    BackendFactory,
    Provider,
    add_provider,
    connect,
    make_backend,
)
from vcage.backends.retry import Failure
from vcage.backends.usage import Usage

__all__ = [
    "BACKENDS",
    "PROVIDERS",
    "BackendConfig",
    "BackendFactory",
    "ChatBackend",
    "Failure",
    "Message",
    "OpenAIChatBackend",
    "Provider",
    "Usage",
    "add_provider",
    "connect",
    "encode_png",
    "make_backend",
]
