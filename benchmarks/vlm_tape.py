"""A local OpenAI-compatible chat endpoint that records a vision model's answers, or replays them.

A VLM critic measured on a benchmark talks to this server (``base_url``), never to the model itself:

- recording (``upstream`` given): every ``POST /chat/completions`` is forwarded to the upstream
  endpoint with its API key, and each answer (HTTP 200) is appended to the tape, a JSON-lines file;
  errors (rate limits, outages) are passed on to the client, which retries, and are not kept;
  ``GET /models`` is forwarded too. What the tape already holds is answered from it, so recording
  again after an interruption asks the model only what is missing;
- replaying (no upstream): each request is answered from the tape, so a measurement is reproduced
  without the endpoint, its key or its cost. A request that is not on the tape is answered 404 with
  a message saying so (the backend raises, nothing is made up).

A request is identified by the SHA-256 of its model and messages (text and images, as sent) and by
how many times the same request came before in this run (votes ask the same question again), so a
recording is replayed answer for answer. Recording appends; a tape holds one model's answers.
"""

from __future__ import annotations

import hashlib
import json
import threading
import urllib.error
import urllib.request
from collections import Counter
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from vcage.backends import BackendConfig


def request_key(body: dict[str, Any]) -> str:
    """The identity of a chat request: its model and messages, hashed."""
    data = json.dumps({"model": body.get("model"), "messages": body.get("messages")}, sort_keys=True)
    return hashlib.sha256(data.encode()).hexdigest()


def tape_model(path: Path) -> str | None:
    """The model whose answers the tape at ``path`` holds (None: empty or absent tape)."""
    if not path.is_file():
        return None
    for line in path.read_text().splitlines():
        if line.strip():
            return str(json.loads(line)["model"])
    return None


class Tape:
    """The server; use as a context manager, then point a backend at :attr:`base_url`."""

    def __init__(self, path: str | Path, upstream: BackendConfig | None = None) -> None:
        self.path = Path(path)
        self.upstream = upstream
        if upstream is None and not self.path.is_file():
            raise FileNotFoundError(f"no tape at {self.path}: record one first (against a real endpoint)")
        self.answers: dict[tuple[str, int], dict[str, Any]] = {}
        for line in self.path.read_text().splitlines() if self.path.is_file() else []:
            if line.strip():
                entry = json.loads(line)
                self.answers[(entry["key"], entry["n"])] = entry
        self.seen: Counter[str] = Counter()
        self.served = 0  # chat requests answered (from the tape or the model)
        self._lock = threading.Lock()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler())
        self._thread = threading.Thread(target=self._server.serve_forever, daemon=True)

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self._server.server_address[1]}/v1"

    def __enter__(self) -> Tape:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._server.shutdown()
        self._server.server_close()

    # -- answers ----------------------------------------------------------------------------------

    def chat(self, body: dict[str, Any]) -> tuple[int, dict[str, Any]]:
        key = request_key(body)
        with self._lock:
            n = self.seen[key]
            entry = self.answers.get((key, n))
            if entry is not None:  # on the tape already (recording again only adds what is missing)
                self.seen[key] += 1
                self.served += 1
                return 200, entry["response"]
        if self.upstream is None:
            return 404, {"error": {"message": f"this request (answer {n + 1} to it) is not on the tape "
                                              f"{self.path}: record it against a real endpoint",
                                   "type": "not_found_error"}}
        status, response = self._forward("chat/completions", body)
        if status != 200:  # not an answer of the model (a rate limit, an outage): passed on, not kept
            return status, response
        entry = {"key": key, "n": n, "model": body.get("model"), "response": response}
        with self._lock:
            with self.path.open("a") as f:
                f.write(json.dumps(entry) + "\n")
            self.answers[(key, n)] = entry
            self.seen[key] += 1
            self.served += 1
        return status, response

    def models(self) -> tuple[int, dict[str, Any]]:
        if self.upstream is not None:
            return self._forward("models", None)
        model = tape_model(self.path)
        return 200, {"object": "list", "data": [{"id": model, "object": "model"}] if model else []}

    def _forward(self, route: str, body: dict[str, Any] | None) -> tuple[int, dict[str, Any]]:
        assert self.upstream is not None
        url = f"{self.upstream.base_url.rstrip('/')}/{route}"
        data = json.dumps(body).encode() if body is not None else None
        headers = {"Content-Type": "application/json",
                   "Authorization": f"Bearer {self.upstream.resolve_api_key()}"}
        request = urllib.request.Request(url, data=data, method="POST" if body is not None else "GET",
                                         headers=headers)
        try:
            with urllib.request.urlopen(request, timeout=self.upstream.timeout) as reply:  # noqa: S310
                return reply.status, json.loads(reply.read() or b"{}")
        except urllib.error.HTTPError as exc:
            try:
                payload = json.loads(exc.read() or b"{}")
            except json.JSONDecodeError:
                payload = {"error": {"message": f"upstream answered HTTP {exc.code}"}}
            return exc.code, payload

    def _handler(self) -> type[BaseHTTPRequestHandler]:
        tape = self

        class Handler(BaseHTTPRequestHandler):
            def do_POST(self) -> None:  # noqa: N802 - http.server's name
                if not self.path.rstrip("/").endswith("/chat/completions"):
                    self._send(404, {"error": {"message": f"no route {self.path}"}})
                    return
                body = json.loads(self.rfile.read(int(self.headers.get("Content-Length", 0))) or b"{}")
                self._send(*tape.chat(body))

            def do_GET(self) -> None:  # noqa: N802
                if not self.path.rstrip("/").endswith("/models"):
                    self._send(404, {"error": {"message": f"no route {self.path}"}})
                    return
                self._send(*tape.models())

            def _send(self, status: int, payload: dict[str, Any]) -> None:
                data = json.dumps(payload).encode()
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def log_message(self, *args: object) -> None:  # quiet
                pass

        return Handler
