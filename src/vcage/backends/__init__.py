"""Provider transport for LLM planners and VLM critics. Depends on vcage core only: no MuJoCo import.

``connect(BackendConfig(...))`` builds the :class:`ChatBackend` registered for the config's provider
(``openai``: any OpenAI-compatible server; ``gemini``: Google's Gemini API); ``BackendConfig.from_env``
reads the ``VCAGE_LLM_*`` / ``VCAGE_VLM_*`` variables.
"""

from vcage.backends.base import (
    BACKENDS,
    BackendConfig,
    BackendFactory,
    ChatBackend,
    Failure,
    Message,
    Usage,
    connect,
    encode_png,
    make_backend,
)
from vcage.backends.openai_compat import OpenAIChatBackend


def _gemini(config: BackendConfig) -> ChatBackend:
    from vcage.backends.gemini import GeminiChatBackend  # google-genai takes ~0.5 s to import

    return GeminiChatBackend(config)


BACKENDS.add("gemini", _gemini)

__all__ = [
    "BACKENDS",
    "BackendConfig",
    "BackendFactory",
    "ChatBackend",
    "Failure",
    "Message",
    "OpenAIChatBackend",
    "Usage",
    "connect",
    "encode_png",
    "make_backend",
]
