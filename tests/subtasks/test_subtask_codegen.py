"""A model writes the programs: a real local OpenAI-compatible server replays its completions."""

from __future__ import annotations

import pytest

from backends.fake_openai import FakeOpenAI
from vcage.backends import BackendConfig, connect
from vcage.scene.spec import ObjectSpec, SceneSpec
from vcage.subtasks.candidates import candidates
from vcage.subtasks.codegen import ProgramWriter, dry_run, extract_program
from vcage.subtasks.verify import static_check

SCENE = SceneSpec(objects=(ObjectSpec("cube", "block", (0.45, -0.12)),
                           ObjectSpec("dish", "plate", (0.55, 0.12))))
GOOD = "```python\nd = position('dish')\npick_and_place(obj='cube', target='dish')\n```"


@pytest.fixture()
def server():  # type: ignore[no-untyped-def]
    with FakeOpenAI() as fake:
        yield fake


def _writer(server: FakeOpenAI) -> ProgramWriter:
    return ProgramWriter(connect(BackendConfig(base_url=server.base_url, model="fake-model", max_retries=0)))


def test_a_good_completion_becomes_the_candidates_code(server: FakeOpenAI) -> None:
    (cand,) = candidates("s", SCENE)
    server.script(GOOD)
    out = _writer(server).write(cand, SCENE)
    assert out.source == "llm" and out.model == "fake-model" and len(out.prompt_hash or "") == 64
    assert out.code == "d = position('dish')\npick_and_place(obj='cube', target='dish')\n"
    prompt = server.requests[0]["messages"]
    assert "pick_and_place(obj, target=None" in prompt[0]["content"]  # the skill API
    assert "on(cube, dish)" in prompt[1]["content"] and "cube: a block at x=0.450" in prompt[1]["content"]
    assert static_check(out, SCENE) is None


def test_errors_are_fed_back_until_the_program_is_right(server: FakeOpenAI) -> None:
    (cand,) = candidates("s", SCENE)
    server.script("Sure! First pick up the cube, then put it on the dish.",  # prose, not code
                  "```python\nimport os\nos.system('id')\n```",  # malicious
                  GOOD)
    writer = _writer(server)
    out = writer.write(cand, SCENE)
    assert writer.replies == 3 and "pick_and_place(obj='cube'" in out.code
    second, third = server.requests[1]["messages"], server.requests[2]["messages"]
    assert second[-1]["content"].startswith("That program fails: rejected: ")
    assert "not valid Python" in second[-1]["content"]
    assert "import (programs may not import anything" in third[-1]["content"]
    assert third[-2]["content"].startswith("```python\nimport os")  # the model's own reply, kept


def test_a_program_still_wrong_after_the_repairs_is_kept_and_recorded_invalid(server: FakeOpenAI) -> None:
    (cand,) = candidates("s", SCENE)
    near_miss = "```python\npick_and_place(obj='cube', xy=(1.5, 0.0))\n```"  # off the table
    server.script(near_miss, near_miss, near_miss)
    out = _writer(server).write(cand, SCENE)
    assert len(server.requests) == 3
    problem = static_check(out, SCENE)
    assert problem is None  # statically fine: the off-table call is refused when trials run it
    assert "is off the table" in (dry_run(out.code, SCENE) or "")


def test_the_code_of_a_reply() -> None:
    assert extract_program("Here:\n```py\nretreat()\n```\nDone.") == "retreat()\n"
    assert extract_program("retreat()") == "retreat()\n"
