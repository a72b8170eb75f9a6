"""The VLM critic against a local OpenAI-protocol server: votes, malformed answers, failures."""

from __future__ import annotations

import json
from collections.abc import Iterator

import numpy as np
import pytest

from backends.fake_openai import Delay, FakeOpenAI, Status
from vcage.backends import BackendConfig, make_backend
from vcage.critics.base import CriticConfig, Observation, View
from vcage.critics.vlm import VLMCritic, parse_answer
from vcage.errors import ConfigError
from vcage.planning.goals import put_on

YES = json.dumps({"success": True, "reason": "the mouse is on the pad"})
NO = json.dumps({"success": False, "reason": "the mouse is beside the pad"})


def _obs() -> Observation:
    img = np.zeros((24, 32, 3), np.uint8)
    seg = np.full((24, 32), -1, np.int32)
    views = {"top": View(img, seg), "front": View(img + 50, seg)}
    return Observation(subtask=put_on("mouse", "pad", "the mouse lies on the pad"),
                       labels=("mouse", "pad"), before=views, after=views)


@pytest.fixture()
def server() -> Iterator[FakeOpenAI]:
    with FakeOpenAI() as srv:
        yield srv


def _critic(server: FakeOpenAI, timeout: float = 5.0, retries: int = 0, **cfg: object) -> VLMCritic:
    backend = make_backend("openai", BackendConfig(base_url=server.base_url, model="fake-vlm",
                                                   timeout=timeout, max_retries=retries, backoff=0.01))
    return VLMCritic(backend, CriticConfig("vlm", **cfg))  # type: ignore[arg-type]


def test_yes_accepts_and_sends_three_images(server: FakeOpenAI) -> None:
    server.script(YES)
    verdict = _critic(server).judge(_obs())
    assert verdict.accept and "1/1 votes yes" in verdict.reason
    content = server.requests[0]["messages"][1]["content"]
    images = [p for p in content if p["type"] == "image_url"]
    assert len(images) == 3 and images[0]["image_url"]["url"].startswith("data:image/png;base64,")
    assert "the mouse lies on the pad" in content[0]["text"]


def test_no_rejects_with_the_models_reason(server: FakeOpenAI) -> None:
    server.script("```json\n" + NO + "\n```")
    verdict = _critic(server).judge(_obs())
    assert not verdict.accept and "beside the pad" in verdict.reason


def test_majority_and_unanimous_votes(server: FakeOpenAI) -> None:
    server.script(YES, NO, YES)
    assert _critic(server, votes=3).judge(_obs()).accept
    server.script(YES, NO, YES)
    assert not _critic(server, votes=3, rule="all").judge(_obs()).accept


def test_malformed_answers_count_as_configured_and_are_logged(server: FakeOpenAI) -> None:
    server.script("sure, looks fine to me")
    verdict = _critic(server).judge(_obs())
    assert not verdict.accept and verdict.details["malformed"] == 1
    server.script('{"success": "maybe"}')
    lenient = _critic(server, malformed_verdict=True).judge(_obs())
    assert lenient.accept and lenient.details["malformed"] == 1


def test_timeouts_and_rate_limits_never_crash_the_run(server: FakeOpenAI) -> None:
    server.script(Status(429, "slow down", retry_after=0.01), YES)
    assert _critic(server, retries=1).judge(_obs()).accept
    server.script(Delay(2.0, then=YES))
    verdict = _critic(server, timeout=0.2).judge(_obs())
    assert not verdict.accept and "no answer" in verdict.reason and verdict.details["malformed"] == 1


def test_answer_parsing_and_config_checks() -> None:
    assert parse_answer('{"answer": "yes", "reason": "ok"}') == {"success": True, "reason": "ok"}
    assert parse_answer("[true]") is None
    with pytest.raises(ConfigError):
        CriticConfig("vlm", votes=0)
    with pytest.raises(ConfigError):
        CriticConfig("vlm", rule="some")
