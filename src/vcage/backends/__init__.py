"""Provider transport for LLM planners and VLM critics. Depends on vcage core only: no MuJoCo import.

``make_backend("openai", BackendConfig(...))`` builds a :class:`ChatBackend` from the ``BACKENDS`` registry.
"""

from vcage.backends.base import (
    BACKENDS,
    BackendConfig,
    BackendFactory,
    ChatBackend,
    Message,
    Usage,
    encode_png,
    make_backend,
)
from vcage.backends.openai_compat import OpenAIChatBackend

__all__ = [
    "BACKENDS",
    "BackendConfig",
    "BackendFactory",
    "ChatBackend",
    "Message",
    "OpenAIChatBackend",
    "Usage",
    "encode_png",
    "make_backend",
]
