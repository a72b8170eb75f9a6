"""OpenAI-compatible backend: the real SDK over real HTTP to a local scripted server (no key, no internet)."""

from __future__ import annotations

import base64
import io
import json
import subprocess
import sys
import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from PIL import Image

from vcage.backends import BACKENDS, BackendConfig, ChatBackend, Message, OpenAIChatBackend, make_backend
from vcage.backends.retry import Failure
from vcage.errors import (
    BackendError,
    BackendTimeout,
    BackendUnavailableError,
    ConfigError,
    EmptyReplyError,
    MissingAPIKeyError,
    RegistryError,
)

from .fake_openai import Delay, FakeOpenAI, Reply, Status


@pytest.fixture()
def server() -> Iterator[FakeOpenAI]:
    with FakeOpenAI() as srv:
        yield srv


@pytest.fixture(autouse=True)
def _close_backends() -> Iterator[None]:
    yield
    while _OPEN:
        _OPEN.pop().close()


_OPEN: list[ChatBackend] = []


@pytest.fixture(autouse=True)
def _no_key_in_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)


def config(server: FakeOpenAI, **kw: Any) -> BackendConfig:
    fields: dict[str, Any] = {"base_url": server.base_url, "model": "qwen2.5-vl", "timeout": 2.0,
                              "max_retries": 2, "backoff": 0.01, "max_backoff": 0.5}
    fields.update(kw)
    return BackendConfig(**fields)


def backend(server: FakeOpenAI, **kw: Any) -> ChatBackend:
    """A backend for ``server`` with fast test settings; closed after the test."""
    _OPEN.append(make_backend("openai", config(server, **kw)))
    return _OPEN[-1]


def test_valid_reply_and_request_fields(server: FakeOpenAI) -> None:
    server.script('{"subtasks": []}')
    b = backend(server, temperature=0.3, max_tokens=256)
    text = b.chat([Message("system", "You plan."), Message("user", "tidy the desk")], json_mode=True)
    assert text == '{"subtasks": []}'
    (req,) = server.requests
    assert req["model"] == "qwen2.5-vl"
    assert req["messages"] == [{"role": "system", "content": "You plan."},
                               {"role": "user", "content": "tidy the desk"}]
    assert req["temperature"] == 0.3 and req["max_tokens"] == 256
    assert req["response_format"] == {"type": "json_object"}
    assert server.headers[0]["authorization"] == "Bearer EMPTY"  # local server: placeholder key
    usage = b.usage
    assert (usage.requests, usage.retries, usage.prompt_tokens, usage.completion_tokens) == (1, 0, 11, 7)


def test_plain_mode_sends_no_response_format(server: FakeOpenAI) -> None:
    server.script("ok")
    assert backend(server).chat([Message("user", "hi")]) == "ok"
    assert "response_format" not in server.requests[0]


def test_images_sent_as_base64_png_parts(server: FakeOpenAI) -> None:
    server.script('{"accept": true}')
    rgb = np.zeros((6, 8, 3), np.uint8)
    rgb[..., 0] = 200
    buf = io.BytesIO()
    Image.new("RGB", (3, 2), (0, 0, 255)).save(buf, format="PNG")
    backend(server).chat([Message("user", "Is the cup on the plate?", images=(rgb, buf.getvalue()))])
    parts = server.requests[0]["messages"][0]["content"]
    assert parts[0] == {"type": "text", "text": "Is the cup on the plate?"}
    urls = [p["image_url"]["url"] for p in parts[1:]]
    assert [p["type"] for p in parts[1:]] == ["image_url", "image_url"]
    assert all(u.startswith("data:image/png;base64,") for u in urls)
    decoded = [np.asarray(Image.open(io.BytesIO(base64.b64decode(u.split(",", 1)[1])))) for u in urls]
    np.testing.assert_array_equal(decoded[0], rgb)
    assert base64.b64decode(urls[1].split(",", 1)[1]) == buf.getvalue()


def test_bad_images_and_roles_rejected() -> None:
    with pytest.raises(ConfigError, match="uint8"):
        Message("user", "x", images=(np.zeros((4, 4), np.float32),))
    with pytest.raises(ConfigError, match="PNG"):
        Message("user", "x", images=(b"\xff\xd8\xff jpeg",))
    with pytest.raises(ConfigError, match="user"):
        Message("system", "x", images=(np.zeros((2, 2, 3), np.uint8),))
    with pytest.raises(ConfigError, match="role"):
        Message("robot", "x")


def test_malformed_content_returned_as_is(server: FakeOpenAI) -> None:
    bad = "Sure! Here is the plan: {not json"
    server.script(bad)
    assert backend(server).chat([Message("user", "plan")], json_mode=True) == bad


def test_missing_content_raises(server: FakeOpenAI) -> None:
    server.script(Reply(None))
    with pytest.raises(EmptyReplyError, match="no message content") as info:
        backend(server).chat([Message("user", "plan")])
    assert not isinstance(info.value, BackendUnavailableError)  # the server answered


def test_429_then_success_retries_once_honouring_retry_after(server: FakeOpenAI) -> None:
    server.script(Status(429, "slow down", retry_after="0.2"), "done")
    b = backend(server, backoff=0.01)
    assert b.chat([Message("user", "hi")]) == "done"
    assert (b.usage.requests, b.usage.retries) == (2, 1)
    assert b.usage.wait_s == pytest.approx(0.2)  # the server's wait, not backoff 0.01


def test_retry_after_is_capped(server: FakeOpenAI) -> None:
    server.script(Status(429, retry_after="3600"), Status(503, retry_after_ms="5000"), "done")
    b = backend(server, max_backoff=0.05)
    assert b.chat([Message("user", "hi")]) == "done"
    assert b.usage.retries == 2 and b.usage.wait_s == pytest.approx(0.1)


def test_persistent_500_raises_after_all_retries(server: FakeOpenAI) -> None:
    server.script(*[Status(500, "model crashed")] * 3)
    b = backend(server, max_retries=2, backoff=0.01)
    with pytest.raises(BackendError) as info:
        b.chat([Message("user", "hi")])
    err = info.value
    assert not isinstance(err, BackendTimeout) and isinstance(err, BackendUnavailableError)
    assert err.status == 500 and err.model == "qwen2.5-vl"
    assert err.endpoint == server.base_url + "/chat/completions"
    assert "HTTP 500" in str(err) and "model crashed" in str(err) and err.endpoint in str(err)
    assert "3 attempts" in str(err)
    assert len(server.requests) == 3 and b.usage.retries == 2
    assert b.usage.wait_s == pytest.approx(0.01 + 0.02)  # backoff * 2**attempt


def test_timeout_raises_backend_timeout_after_retries(server: FakeOpenAI) -> None:
    server.script(Delay(2.0), Delay(2.0))
    b = backend(server, timeout=0.15, max_retries=1)
    with pytest.raises(BackendTimeout, match="timed out after 2 attempts") as info:
        b.chat([Message("user", "hi")])
    assert isinstance(info.value, BackendUnavailableError)  # a timeout is an outage too
    assert len(server.requests) == 2 and b.usage.retries == 1


def test_400_fails_without_retry(server: FakeOpenAI) -> None:
    server.script(Status(400, "response_format json_object is not supported"), "never sent")
    b = backend(server)
    with pytest.raises(BackendError, match="HTTP 400: response_format json_object") as info:
        b.chat([Message("user", "hi")], json_mode=True)
    assert info.value.status == 400 and not isinstance(info.value, BackendUnavailableError)
    assert len(server.requests) == 1 and b.usage.retries == 0 and server.remaining == 1


def test_connection_refused_is_backend_error() -> None:
    with FakeOpenAI() as stopped:
        pass
    b = backend(stopped, max_retries=1)  # nothing listens on its port any more
    with pytest.raises(BackendUnavailableError, match="connection failed"):
        b.chat([Message("user", "hi")])
    assert b.usage.requests == 2


def test_empty_script_answers_500_with_clear_message(server: FakeOpenAI) -> None:
    with pytest.raises(BackendError, match="script is empty"):
        backend(server, max_retries=0).chat([Message("user", "hi")])


def test_missing_key_for_remote_url_fails_before_any_request(server: FakeOpenAI) -> None:
    remote = BackendConfig(base_url="https://api.example.com/v1", model="gpt-x", api_key_env="VCAGE_TEST_KEY")
    with pytest.raises(MissingAPIKeyError, match="VCAGE_TEST_KEY") as info:
        make_backend("openai", remote)
    assert "api_key" in str(info.value)
    assert server.requests == []


def test_key_resolution_order(monkeypatch: pytest.MonkeyPatch) -> None:
    remote = BackendConfig(base_url="https://api.example.com/v1", model="m", api_key_env="VCAGE_TEST_KEY")
    monkeypatch.setenv("VCAGE_TEST_KEY", "from-env")
    assert remote.resolve_api_key() == "from-env"
    explicit = BackendConfig(base_url="https://api.example.com/v1", model="m", api_key="explicit",
                             api_key_env="VCAGE_TEST_KEY")
    assert explicit.resolve_api_key() == "explicit"
    for host in ("localhost", "127.0.0.1", "[::1]"):
        assert BackendConfig(base_url=f"http://{host}:11434/v1", model="m").resolve_api_key() == "EMPTY"


def test_env_key_is_sent(server: FakeOpenAI, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPENAI_API_KEY", "sk-local-test")
    server.script("ok")
    backend(server).chat([Message("user", "hi")])
    assert server.headers[0]["authorization"] == "Bearer sk-local-test"


@pytest.mark.parametrize(
    ("field", "value"),
    [("model", ""), ("timeout", 0.0), ("timeout", -1.0), ("max_retries", -1), ("base_url", "ftp://host/v1"),
     ("base_url", "localhost:8000/v1"), ("backoff", -0.1), ("temperature", 3.0), ("max_tokens", 0),
     ("breaker_failures", 0), ("breaker_failures", True), ("breaker_failures", 2.0),
     ("max_backoff", float("inf"))],
)
def test_config_validation_names_field(field: str, value: Any) -> None:
    data: dict[str, Any] = {"base_url": "http://localhost:8000/v1", "model": "m", field: value}
    with pytest.raises(ConfigError, match=field):
        BackendConfig(**data)


def test_to_dict_has_no_secret_and_round_trips() -> None:
    cfg = BackendConfig(base_url="https://api.example.com/v1", model="m", api_key="sk-secret", timeout=5.0)
    data = cfg.to_dict()
    assert "api_key" not in data and data["api_key_env"] == "OPENAI_API_KEY"
    assert "sk-secret" not in json.dumps(data) and "sk-secret" not in repr(cfg)
    assert BackendConfig.from_dict(data) == cfg
    with pytest.raises(ConfigError, match="valid keys"):
        BackendConfig.from_dict({**data, "modle": "x"})


def test_reliability_settings_round_trip_and_are_used(server: FakeOpenAI) -> None:
    cfg = config(server, timeout=0.25, max_retries=1, backoff=0.03, max_backoff=0.04, breaker_failures=2)
    data = cfg.to_dict()
    assert {k: data[k] for k in ("timeout", "max_retries", "backoff", "max_backoff", "breaker_failures")} == {
        "timeout": 0.25, "max_retries": 1, "backoff": 0.03, "max_backoff": 0.04, "breaker_failures": 2}
    assert BackendConfig.from_dict(json.loads(json.dumps(data))) == cfg
    older = {k: v for k, v in data.items() if k != "breaker_failures"}  # written before the field existed
    assert BackendConfig.from_dict(older).breaker_failures == 3
    server.script(Status(500), Status(500), Delay(2.0), Delay(2.0), "never sent")
    with make_backend("openai", cfg) as b:
        with pytest.raises(BackendUnavailableError, match="HTTP 500"):
            b.chat([Message("user", "hi")])
        assert (b.usage.requests, b.usage.wait_s) == (2, pytest.approx(0.03))  # max_retries, backoff
        with pytest.raises(BackendTimeout, match=r"timeout 0.25 s each"):
            b.chat([Message("user", "hi")])
        assert b.usage.wait_s == pytest.approx(0.03 + 0.03)  # second request: same first wait
        with pytest.raises(BackendUnavailableError, match="circuit open after 2 consecutive"):
            b.chat([Message("user", "hi")])
        assert len(server.requests) == 4 and server.remaining == 1


def test_failures_that_mean_the_endpoint_is_unavailable() -> None:
    unavailable = [Failure(retry=True, detail="timed out", timed_out=True),
                   Failure(retry=True, detail="connection failed"),
                   *(Failure.http(s, "x") for s in (401, 403, 404, 429, 500, 502, 503, 504))]
    answered = [Failure(retry=False, detail="APIResponseValidationError"),
                *(Failure.http(s, "x") for s in (400, 409, 413, 422))]
    assert all(f.unavailable for f in unavailable)
    assert not any(f.unavailable for f in answered)


def test_breaker_counts_concurrent_failures_exactly(server: FakeOpenAI) -> None:
    server.script(*[Status(500)] * 8)
    b = backend(server, max_retries=0, breaker_failures=9)
    errors: list[Exception] = []

    def ask() -> None:
        try:
            b.chat([Message("user", "hi")])
        except BackendError as exc:
            errors.append(exc)

    threads = [threading.Thread(target=ask) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(errors) == 8 and b.breaker.failures == 8 and not b.breaker.is_open
    server.script(Status(500), "never sent")
    with pytest.raises(BackendUnavailableError, match="HTTP 500"):
        b.chat([Message("user", "hi")])
    assert b.breaker.is_open
    with pytest.raises(BackendUnavailableError, match="circuit open after 9"):
        b.chat([Message("user", "hi")])
    assert len(server.requests) == 9 and b.usage.requests == 9
    b.reset()
    assert b.chat([Message("user", "hi")]) == "never sent" and b.breaker.failures == 0


def test_from_env() -> None:
    env = {"VCAGE_LLM_BASE_URL": "http://localhost:11434/v1", "VCAGE_LLM_MODEL": "llava",
           "VCAGE_LLM_API_KEY": "sk-env"}
    cfg = BackendConfig.from_env(environ=env, timeout=7.0)
    assert (cfg.base_url, cfg.model, cfg.timeout) == ("http://localhost:11434/v1", "llava", 7.0)
    assert cfg.api_key_env == "VCAGE_LLM_API_KEY"
    assert cfg.resolve_api_key(env) == "sk-env" and "sk-env" not in json.dumps(cfg.to_dict())
    with pytest.raises(ConfigError, match="VCAGE_LLM_MODEL"):
        BackendConfig.from_env(environ={})


def test_registry() -> None:
    assert "openai" in BACKENDS.names()
    assert BACKENDS.get("openai") is OpenAIChatBackend
    with pytest.raises(RegistryError, match="valid names: .*openai"):
        make_backend("antropic", BackendConfig(base_url="http://localhost:8000/v1", model="m"))


def test_models_endpoint(server: FakeOpenAI) -> None:
    import openai

    with openai.OpenAI(base_url=server.base_url, api_key="EMPTY", max_retries=0) as client:
        assert [m.id for m in client.models.list()] == ["fake-model"]


def test_backends_do_not_import_mujoco() -> None:
    code = "import sys, vcage.backends; assert 'mujoco' not in sys.modules, 'vcage.backends imported mujoco'"
    subprocess.run([sys.executable, "-c", code], check=True)
