"""A local HTTP server speaking OpenAI's chat-completions protocol, driven by a script.

The protocol lives in four methods (``serves``, ``listing``, ``success``, ``error``); ``fake_gemini``
overrides them to speak Gemini's ``generateContent`` with the same scripting.

Use from any test (``tests/`` is on ``sys.path`` through ``tests/conftest.py``)::

    from backends.fake_openai import FakeOpenAI, Reply, Status, Delay

    with FakeOpenAI() as server:
        server.script("first reply", Status(429, retry_after="0.1"), Reply('{"ok": true}'))
        cfg = BackendConfig(base_url=server.base_url, model="m")
        ...
        server.requests  # every request body received, parsed JSON, in order

Each ``POST /v1/chat/completions`` consumes the next scripted item: a reply text (``str`` or
:class:`Reply`), an HTTP error in OpenAI's error format (:class:`Status`), a :class:`Delay` (sleep,
then answer with its ``then`` item, usually after the client gave up), or a callable that receives the
request body and returns one of those. An empty script answers 500 with a message saying so.
``GET /v1/models`` lists the served models (``server.models``, by default the one it was made with);
``server.gets`` holds the paths of GET requests, and ``server.listing_error`` (a :class:`Status` or
:class:`Delay`) makes every GET answer with it instead.
"""

from __future__ import annotations

import json
import threading
import time
import uuid
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

ERROR_TYPES = {400: "invalid_request_error", 401: "authentication_error", 403: "permission_error",
               404: "not_found_error", 429: "rate_limit_error"}


@dataclass(frozen=True)
class Reply:
    """A successful completion; ``text=None`` sends a message without content."""

    text: str | None
    finish_reason: str = "stop"
    prompt_tokens: int = 11
    completion_tokens: int = 7


@dataclass(frozen=True)
class Status:
    """An HTTP error with an OpenAI-format body and optional ``Retry-After`` / ``retry-after-ms``."""

    status: int
    message: str = "scripted error"
    retry_after: str | None = None
    retry_after_ms: str | None = None
    retry_delay: str | None = None  # Gemini only: a google.rpc.RetryInfo detail, e.g. "0.2s"


@dataclass(frozen=True)
class Delay:
    """Sleep ``seconds`` (cut short when the server closes), then answer with ``then``."""

    seconds: float
    then: Reply | Status | str = "late reply"


@dataclass(frozen=True)
class Raw:
    """Any JSON answer, sent as it is: for protocols whose answers :class:`Reply` cannot describe
    (image answers, prompt blocks); see :mod:`fake_images`."""

    status: int
    payload: dict[str, Any]
    headers: tuple[tuple[str, str], ...] = ()


Item = str | Reply | Status | Delay | Raw | Callable[[dict[str, Any]], "str | Reply | Status | Delay | Raw"]


class FakeOpenAI:
    """A scripted OpenAI-compatible server on 127.0.0.1 and a free port, in a background thread."""

    def __init__(self, model: str = "fake-model") -> None:
        self.model = model
        self.models: list[str] = [model]  # what GET /v1/models lists
        self.listing_error: Status | Delay | None = None  # answer every GET with this instead
        self.gets: list[str] = []  # paths of GET requests, in arrival order
        self.requests: list[dict[str, Any]] = []  # request bodies, in arrival order
        self.headers: list[dict[str, str]] = []  # request headers, same order
        self._script: deque[Item] = deque()
        self._lock = threading.Lock()
        self._closing = threading.Event()
        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), _handler_class(self))
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(
            target=self._httpd.serve_forever, kwargs={"poll_interval": 0.02}, name="FakeOpenAI", daemon=True
        )

    @property
    def base_url(self) -> str:
        host, port = self._httpd.server_address[:2]
        return f"http://{host!s}:{port}/v1"

    def script(self, *items: Item) -> FakeOpenAI:
        """Queue responses, one per expected chat request."""
        with self._lock:
            self._script.extend(items)
        return self

    @property
    def remaining(self) -> int:
        with self._lock:
            return len(self._script)

    def start(self) -> FakeOpenAI:
        self._thread.start()
        return self

    def close(self) -> None:
        self._closing.set()
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(timeout=5)

    def __enter__(self) -> FakeOpenAI:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _next(self, body: dict[str, Any], headers: dict[str, str]) -> Item | None:
        with self._lock:
            self.requests.append(body)
            self.headers.append(headers)
            return self._script.popleft() if self._script else None

    def _sleep(self, seconds: float) -> None:
        self._closing.wait(seconds)

    # The protocol: subclasses for other providers override these four.
    def serves(self, path: str) -> bool:
        """Whether ``POST path`` is a chat request."""
        return path.rstrip("/") == "/v1/chat/completions"

    def listing(self, path: str) -> dict[str, Any] | None:
        """The answer to ``GET path``, or None for 404."""
        if path.rstrip("/") != "/v1/models":
            return None
        data = [{"id": m, "object": "model", "created": 0, "owned_by": "fake-openai"} for m in self.models]
        return {"object": "list", "data": data}

    def parse(self, raw: bytes, content_type: str) -> dict[str, Any]:
        """The request body of a served POST as a dict; ValueError answers 400."""
        body: dict[str, Any] = json.loads(raw)
        return body

    def not_found(self, method: str, path: str) -> str:
        """The message of a 404 for ``method path``."""
        return f"no route {method} {path}"

    def success(self, path: str, body: dict[str, Any], reply: Reply) -> dict[str, Any]:
        return completion(str(body.get("model", self.model)), reply)

    def error(self, status: int, message: str, retry_delay: str | None = None) -> dict[str, Any]:
        return error_body(status, message)


def completion(model: str, reply: Reply) -> dict[str, Any]:
    """A chat.completion object in OpenAI's response schema."""
    return {
        "id": f"chatcmpl-{uuid.uuid4().hex[:12]}",
        "object": "chat.completion",
        "created": int(time.time()),
        "model": model,
        "choices": [{"index": 0, "message": {"role": "assistant", "content": reply.text},
                     "finish_reason": reply.finish_reason}],
        "usage": {"prompt_tokens": reply.prompt_tokens, "completion_tokens": reply.completion_tokens,
                  "total_tokens": reply.prompt_tokens + reply.completion_tokens},
    }


def error_body(status: int, message: str) -> dict[str, Any]:
    """An error object in OpenAI's format."""
    kind = ERROR_TYPES.get(status, "server_error" if status >= 500 else "invalid_request_error")
    return {"error": {"message": message, "type": kind, "param": None, "code": str(status)}}


def _handler_class(server: FakeOpenAI) -> type[BaseHTTPRequestHandler]:
    class Handler(BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"

        def log_message(self, format: str, *args: Any) -> None:  # keep test output quiet
            pass

        def do_GET(self) -> None:  # noqa: N802 - http.server naming
            with server._lock:
                server.gets.append(self.path)
            if server.listing_error is not None:
                self._answer(server.listing_error, {})
                return
            listing = server.listing(self.path)
            if listing is None:
                self._send(404, server.error(404, server.not_found("GET", self.path)))
            else:
                self._send(200, listing)

        def do_POST(self) -> None:  # noqa: N802 - http.server naming
            raw = self.rfile.read(int(self.headers.get("Content-Length") or 0))
            if not server.serves(self.path):
                self._send(404, server.error(404, f"no route POST {self.path}"))
                return
            try:
                body = server.parse(raw, self.headers.get("Content-Type") or "")
            except ValueError:
                self._send(400, server.error(400, "request body is not valid JSON"))
                return
            item = server._next(body, {k.lower(): v for k, v in self.headers.items()})
            self._answer(item, body)

        def _answer(self, item: Item | None, body: dict[str, Any]) -> None:
            if item is None:
                n = len(server.requests)
                msg = (f"{type(server).__name__}: script is empty at request #{n}; script one response "
                       "per expected request")
                self._send(500, server.error(500, msg))
            elif isinstance(item, Delay):
                server._sleep(item.seconds)
                self._answer(item.then, body)
            elif isinstance(item, Status):
                headers = {"Retry-After": item.retry_after, "retry-after-ms": item.retry_after_ms}
                self._send(item.status, server.error(item.status, item.message, item.retry_delay), headers)
            elif isinstance(item, Raw):
                self._send(item.status, item.payload, dict(item.headers))
            elif isinstance(item, (str, Reply)):
                reply = Reply(item) if isinstance(item, str) else item
                self._send(200, server.success(self.path, body, reply))
            else:
                self._answer(item(body), body)

        def _send(
            self, status: int, payload: dict[str, Any], headers: dict[str, str | None] | None = None
        ) -> None:
            data = json.dumps(payload).encode()
            try:
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                for key, value in (headers or {}).items():
                    if value is not None:
                        self.send_header(key, value)
                self.end_headers()
                self.wfile.write(data)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the client gave up (timeout) before the answer

    return Handler
