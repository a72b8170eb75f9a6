"""A local HTTP server speaking the Gemini API's ``generateContent``, scripted like :mod:`fake_openai`.

    from backends.fake_gemini import FakeGemini
    from backends.fake_openai import Reply, Status, Delay

    with FakeGemini() as server:
        server.script('{"accept": true}', Status(429, retry_delay="0.1s"))
        cfg = BackendConfig(base_url=server.base_url, model="gemini-x", provider="gemini")

Requests go to ``POST /{version}/models/{model}:generateContent``; ``server.requests`` holds the
bodies and ``server.paths`` the paths they were sent to. ``GET /{version}/models/{model}`` answers
the model's resource for the models in ``server.models`` and 404 for others, and
``GET /{version}/models`` lists them, as ``models.get`` / ``models.list`` expect.
"""

from __future__ import annotations

import re
from typing import Any

from .fake_openai import FakeOpenAI, Reply

ROUTE = re.compile(r"^/(v1|v1beta)/models/([^/:]+):generateContent$")
MODEL = re.compile(r"^/(v1|v1beta)/models/([^/:]+)$")
LIST = re.compile(r"^/(v1|v1beta)/models/?$")
STATUS_NAMES = {400: "INVALID_ARGUMENT", 401: "UNAUTHENTICATED", 403: "PERMISSION_DENIED",
                404: "NOT_FOUND", 429: "RESOURCE_EXHAUSTED", 500: "INTERNAL", 503: "UNAVAILABLE"}


class FakeGemini(FakeOpenAI):
    """A scripted Gemini API server on 127.0.0.1 and a free port, in a background thread."""

    def __init__(self, model: str = "gemini-fake") -> None:
        super().__init__(model)
        self.paths: list[str] = []

    @property
    def base_url(self) -> str:
        host, port = self._httpd.server_address[:2]
        return f"http://{host!s}:{port}"

    def serves(self, path: str) -> bool:
        if ROUTE.match(path.split("?")[0]) is None:
            return False
        self.paths.append(path)
        return True

    def listing(self, path: str) -> dict[str, Any] | None:
        route = path.split("?")[0]
        if LIST.match(route):
            return {"models": [model_resource(m) for m in self.models]}
        match = MODEL.match(route)
        if match and match.group(2) in self.models:
            return model_resource(match.group(2))
        return None

    def not_found(self, method: str, path: str) -> str:
        match = MODEL.match(path.split("?")[0])
        if method == "GET" and match:
            return f"models/{match.group(2)} is not found for API version {match.group(1)}"
        return super().not_found(method, path)

    def success(self, path: str, body: dict[str, Any], reply: Reply) -> dict[str, Any]:
        parts = [] if reply.text is None else [{"text": reply.text}]
        finish = {"stop": "STOP", "length": "MAX_TOKENS"}.get(reply.finish_reason, "STOP")
        return {
            "candidates": [{"content": {"role": "model", "parts": parts}, "finishReason": finish,
                            "index": 0}],
            "usageMetadata": {"promptTokenCount": reply.prompt_tokens,
                              "candidatesTokenCount": reply.completion_tokens,
                              "totalTokenCount": reply.prompt_tokens + reply.completion_tokens},
            "modelVersion": ROUTE.match(path.split("?")[0]).group(2),  # type: ignore[union-attr]
        }

    def error(self, status: int, message: str, retry_delay: str | None = None) -> dict[str, Any]:
        details = ([{"@type": "type.googleapis.com/google.rpc.RetryInfo", "retryDelay": retry_delay}]
                   if retry_delay is not None else [])
        name = STATUS_NAMES.get(status, "INTERNAL" if status >= 500 else "FAILED_PRECONDITION")
        return {"error": {"code": status, "message": message, "status": name, "details": details}}


def model_resource(name: str) -> dict[str, Any]:
    """A ``Model`` resource as the Gemini API returns it."""
    return {"name": f"models/{name}", "version": "001", "displayName": name,
            "description": "a scripted model", "inputTokenLimit": 1048576, "outputTokenLimit": 8192,
            "supportedGenerationMethods": ["generateContent", "countTokens"]}
