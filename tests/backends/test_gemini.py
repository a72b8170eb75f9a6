"""Gemini backend: the real google-genai SDK over real HTTP to a local server speaking generateContent."""

from __future__ import annotations

import base64
import io
import json
import subprocess
import sys
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from PIL import Image

from vcage.backends import BackendConfig, ChatBackend, Message, connect
from vcage.critics.base import Observation, View
from vcage.critics.vlm import VLMCritic
from vcage.errors import (
    BackendError,
    BackendTimeout,
    BackendUnavailableError,
    ConfigError,
    EmptyReplyError,
    MissingAPIKeyError,
)
from vcage.planning.goals import put_on
from vcage.planning.llm import LLMPlanner

from .fake_gemini import FakeGemini
from .fake_openai import Delay, Reply, Status


@pytest.fixture()
def server() -> Iterator[FakeGemini]:
    with FakeGemini() as srv:
        yield srv


@pytest.fixture(autouse=True)
def _no_key_in_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("GEMINI_API_KEY", raising=False)


_OPEN: list[ChatBackend] = []


@pytest.fixture(autouse=True)
def _close_backends() -> Iterator[None]:
    yield
    while _OPEN:
        _OPEN.pop().close()


def backend(server: FakeGemini, **kw: Any) -> ChatBackend:
    fields: dict[str, Any] = {"base_url": server.base_url, "model": "gemini-test", "provider": "gemini",
                              "timeout": 2.0, "max_retries": 2, "backoff": 0.01, "max_backoff": 0.5}
    fields.update(kw)
    _OPEN.append(connect(BackendConfig(**fields)))
    return _OPEN[-1]


def test_valid_reply_and_request_fields(server: FakeGemini) -> None:
    server.script('{"subtasks": []}')
    b = backend(server, temperature=0.2, max_tokens=128)
    text = b.chat([Message("system", "You plan."), Message("user", "tidy the desk"),
                   Message("assistant", "{}"), Message("user", "again")], json_mode=True)
    assert text == '{"subtasks": []}'
    assert server.paths == ["/v1beta/models/gemini-test:generateContent"]
    (req,) = server.requests
    assert req["systemInstruction"]["parts"] == [{"text": "You plan."}]
    assert [(c["role"], c["parts"][0]["text"]) for c in req["contents"]] == [
        ("user", "tidy the desk"), ("model", "{}"), ("user", "again")]
    gen = req["generationConfig"]
    assert gen["temperature"] == 0.2 and gen["maxOutputTokens"] == 128
    assert gen["responseMimeType"] == "application/json"
    assert server.headers[0]["x-goog-api-key"] == "EMPTY"  # local server: placeholder key
    assert (b.usage.requests, b.usage.prompt_tokens, b.usage.completion_tokens) == (1, 11, 7)
    assert b.endpoint == server.base_url + "/v1beta/models/gemini-test:generateContent"


def test_plain_mode_and_images_as_inline_png(server: FakeGemini) -> None:
    server.script("yes")
    rgb = np.zeros((6, 8, 3), np.uint8)
    rgb[..., 1] = 170
    assert backend(server).chat([Message("user", "Is the cup on the plate?", images=(rgb,))]) == "yes"
    req = server.requests[0]
    assert "responseMimeType" not in req.get("generationConfig", {})
    text, image = req["contents"][0]["parts"]
    assert text == {"text": "Is the cup on the plate?"}
    inline = image.get("inlineData") or image["inline_data"]
    assert inline.get("mimeType", inline.get("mime_type")) == "image/png"
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(base64.b64decode(inline["data"])))), rgb)


def test_malformed_content_returned_as_is_and_empty_content_raises(server: FakeGemini) -> None:
    server.script("Sure! {not json", Reply(None))
    b = backend(server)
    assert b.chat([Message("user", "plan")], json_mode=True) == "Sure! {not json"
    with pytest.raises(EmptyReplyError, match="no message content"):
        b.chat([Message("user", "plan")])


def test_429_retry_waits_what_retry_info_asks(server: FakeGemini) -> None:
    server.script(Status(429, "quota", retry_delay="0.2s"), "done")
    b = backend(server, backoff=0.01)
    assert b.chat([Message("user", "hi")]) == "done"
    assert (b.usage.requests, b.usage.retries) == (2, 1)
    assert b.usage.wait_s == pytest.approx(0.2)


def test_persistent_503_raises_after_all_retries(server: FakeGemini) -> None:
    server.script(*[Status(503, "model overloaded")] * 3)
    b = backend(server, max_retries=2)
    with pytest.raises(BackendError) as info:
        b.chat([Message("user", "hi")])
    err = info.value
    assert not isinstance(err, BackendTimeout) and err.status == 503 and err.model == "gemini-test"
    assert isinstance(err, BackendUnavailableError)
    assert "HTTP 503: model overloaded" in str(err) and "3 attempts" in str(err)
    assert len(server.requests) == 3


def test_timeout_raises_backend_timeout(server: FakeGemini) -> None:
    server.script(Delay(3.0), Delay(3.0))
    b = backend(server, timeout=0.2, max_retries=1)
    with pytest.raises(BackendTimeout, match="timed out after 2 attempts"):
        b.chat([Message("user", "hi")])
    assert len(server.requests) == 2


def test_400_fails_at_once_naming_the_problem(server: FakeGemini) -> None:
    server.script(Status(400, "responseMimeType is not supported by this model"), "never sent")
    with pytest.raises(BackendError, match="HTTP 400: responseMimeType") as info:
        backend(server).chat([Message("user", "hi")], json_mode=True)
    assert info.value.status == 400 and server.remaining == 1


def test_connection_refused_is_backend_error() -> None:
    with FakeGemini() as stopped:
        pass
    with pytest.raises(BackendUnavailableError, match="connection failed"):
        backend(stopped, max_retries=0).chat([Message("user", "hi")])


def test_missing_key_and_env_defaults(monkeypatch: pytest.MonkeyPatch) -> None:
    cfg = BackendConfig.from_env("VCAGE_VLM", environ={"VCAGE_VLM_PROVIDER": "gemini",
                                                       "VCAGE_VLM_MODEL": "gemini-2.5-flash"})
    assert cfg.provider == "gemini" and cfg.base_url == "https://generativelanguage.googleapis.com"
    assert cfg.api_key_env == "GEMINI_API_KEY"
    with pytest.raises(MissingAPIKeyError, match="GEMINI_API_KEY"):
        connect(cfg)
    monkeypatch.setenv("GEMINI_API_KEY", "g-test")
    assert cfg.resolve_api_key() == "g-test"
    with pytest.raises(ConfigError, match="provider 'anthropic' is unknown"):
        BackendConfig(base_url="http://localhost:1/v1", model="m", provider="anthropic")
    with pytest.raises(ConfigError, match="VCAGE_LLM_PROVIDER"):
        BackendConfig.from_env(environ={"VCAGE_LLM_PROVIDER": "claude", "VCAGE_LLM_MODEL": "m"})


def test_llm_planner_and_vlm_critic_through_gemini(server: FakeGemini) -> None:
    plan = {"objects": [{"name": "mouse", "type": "mouse"}, {"name": "pad", "type": "mouse_pad"}],
            "subtasks": [{"skill": "pick_and_place", "args": {"obj": "mouse", "target": "pad"},
                          "description": "the mouse lies on the pad",
                          "predicates": [{"name": "on", "args": ["mouse", "pad"]}]}]}
    server.script("not json", json.dumps(plan), json.dumps({"success": True, "reason": "on the pad"}))
    got = LLMPlanner(backend(server)).plan("tidy the mouse away")
    assert got.subtasks[0].args["target"] == "pad" and len(server.requests) == 2  # one repair
    img = np.zeros((24, 32, 3), np.uint8)
    views = {"top": View(img, np.full((24, 32), -1, np.int32))}
    obs = Observation(subtask=put_on("mouse", "pad", "the mouse lies on the pad"), labels=("mouse", "pad"),
                      before=views, after=views)
    assert VLMCritic(backend(server)).judge(obs).accept


def _obs() -> Observation:
    img = np.zeros((24, 32, 3), np.uint8)
    seg = np.full((24, 32), -1, np.int32)
    views = {"top": View(img, seg), "front": View(img, seg)}
    return Observation(subtask=put_on("mouse", "pad", "the mouse lies on the pad"), labels=("mouse", "pad"),
                       before=views, after=views)


GEMINI_OUTAGES = {
    # name: (script, retries, requests the server sees, text the error must carry)
    "http-503": ([Status(503, "The model is overloaded")] * 2, 1, 2, ["HTTP 503", "The model is overloaded"]),
    "http-429": ([Status(429, "quota exceeded", retry_delay="0.05s")] * 2, 1, 2,
                 ["HTTP 429", "quota exceeded"]),
    "http-401": ([Status(401, "API key not valid")], 2, 1,
                 ["HTTP 401", "API key not valid", "GEMINI_API_KEY"]),
    "stalled": ([Delay(5.0)] * 2, 1, 2, ["timed out after 2 attempts"]),
}


@pytest.mark.parametrize("case", sorted(GEMINI_OUTAGES))
def test_vlm_critic_raises_on_a_gemini_outage(server: FakeGemini, case: str) -> None:
    script, retries, seen, texts = GEMINI_OUTAGES[case]
    server.script(*script)
    critic = VLMCritic(backend(server, timeout=0.3, max_retries=retries))
    t0 = time.monotonic()
    with pytest.raises(BackendUnavailableError) as info:
        critic.judge(_obs())
    assert time.monotonic() - t0 < 10.0
    endpoint = server.base_url + "/v1beta/models/gemini-test:generateContent"
    assert info.value.endpoint == endpoint and endpoint in str(info.value)
    for text in texts:
        assert text in str(info.value)
    assert len(server.requests) == seen


def test_vlm_critic_raises_when_nothing_listens_on_gemini_port() -> None:
    with FakeGemini() as stopped:
        pass
    with pytest.raises(BackendUnavailableError, match="connection failed"):
        VLMCritic(backend(stopped, max_retries=1)).judge(_obs())


def test_gemini_breaker_fails_fast_and_malformed_stays_a_vote(server: FakeGemini) -> None:
    server.script("no json here", Status(500, "internal"), "never sent")
    critic = VLMCritic(backend(server, max_retries=0, breaker_failures=1))
    verdict = critic.judge(_obs())
    assert not verdict.accept and verdict.details["malformed"] == 1
    with pytest.raises(BackendUnavailableError, match="HTTP 500: internal"):
        critic.judge(_obs())
    with pytest.raises(BackendUnavailableError, match="circuit open after 1 consecutive failures"):
        critic.judge(_obs())
    assert len(server.requests) == 2 and server.remaining == 1


def test_gemini_preflight_healthy_unknown_model_and_closed_port(server: FakeGemini) -> None:
    server.models = ["gemini-test"]
    VLMCritic(backend(server)).preflight()
    assert server.gets == ["/v1beta/models/gemini-test"] and server.requests == []
    server.models = ["gemini-2.5-flash", "gemini-2.5-pro"]
    with pytest.raises(BackendUnavailableError) as info:
        backend(server).preflight()
    assert str(info.value).startswith(
        f"model 'gemini-test' is not served at {server.base_url}; served: gemini-2.5-flash, gemini-2.5-pro.")
    server.listing_error = Status(403, "API key not valid for this project")
    with pytest.raises(BackendUnavailableError, match="HTTP 403: API key not valid") as info:
        backend(server, max_retries=3).preflight()
    assert f"preflight request to {server.base_url}/v1beta/models/gemini-test " in str(info.value)
    assert server.requests == []
    with FakeGemini() as stopped:
        pass
    with pytest.raises(BackendUnavailableError, match="connection failed"):
        backend(stopped, max_retries=3).preflight()


def test_gemini_sdk_is_imported_only_when_used() -> None:
    code = ("import sys, vcage.backends, vcage.planning, vcage.critics.vlm; "
            "assert 'google.genai' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
