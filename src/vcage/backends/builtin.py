"""The providers vcage ships, registered when ``vcage.backends`` is imported: one record each.

``openai`` speaks to any OpenAI-compatible server and defaults to vLLM's local address; ``gemini``
is Google's API. The Gemini factory imports its backend only when called, because google-genai takes
about half a second to import and most runs never use it.
"""

from __future__ import annotations

from vcage.backends.base import ChatBackend
from vcage.backends.config import BackendConfig
from vcage.backends.openai_compat import OpenAIChatBackend
from vcage.backends.providers import Provider, add_provider


def _gemini(config: BackendConfig) -> ChatBackend:
    from vcage.backends.gemini import GeminiChatBackend

    return GeminiChatBackend(config)


add_provider(Provider("openai", base_url="http://localhost:8000/v1", api_key_env="OPENAI_API_KEY",
                      factory=OpenAIChatBackend))
add_provider(Provider("gemini", base_url="https://generativelanguage.googleapis.com",
                      api_key_env="GEMINI_API_KEY", factory=_gemini))
