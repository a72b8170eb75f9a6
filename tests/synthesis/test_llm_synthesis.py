"""The LLM chooser and describer over the real openai SDK and a local chat server: catalog names
validated and repaired, "no suitable object" as an answer, ``D_scene`` schema-checked with a bounded
repair loop, and a whole synthesis run with the LLM."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from backends.fake_openai import FakeOpenAI, Status
from vcage.backends import BackendConfig, ChatBackend, connect
from vcage.errors import BackendUnavailableError
from vcage.synthesis.asked import read_prompt
from vcage.synthesis.driver import DirectorySink, SynthesisConfig, shortlist, synthesize, unknown_phrases
from vcage.synthesis.errors import PromptError, SceneDescriptionError
from vcage.synthesis.llm_chooser import Choice, LLMChooser
from vcage.synthesis.llm_describe import LLMDescriber
from vcage.synthesis.retrieval import retriever

SHORT = ("mug", "plate", "cup", "bowl")
MUG_PLATE = Choice((("mug", 1), ("plate", 1)), None, SHORT)


def scene(objects: list[tuple[str, str]], relations: list[tuple[str, str, str]],
          text: str = "A mug stands left of a plate.") -> str:
    return json.dumps({"objects": [{"name": n, "type": t} for n, t in objects],
                       "relations": [{"kind": k, "a": a, "b": b} for k, a, b in relations], "text": text})


@pytest.fixture()
def server() -> Iterator[FakeOpenAI]:
    with FakeOpenAI() as srv:
        yield srv


@pytest.fixture()
def llm(server: FakeOpenAI) -> Iterator[ChatBackend]:
    backend = connect(BackendConfig(base_url=server.base_url, model="fake-model", timeout=5.0, max_retries=1,
                                    backoff=0.01))
    yield backend
    backend.close()


def test_chooser_repairs_names_that_are_not_candidates(server: FakeOpenAI, llm: ChatBackend) -> None:
    server.script('{"objects": [{"type": "coffee mug"}, {"type": "plate"}], "no_match": null}',
                  '```json\n{"objects": [{"type": "mug", "count": 2}, {"type": "plate"}], '
                  '"no_match": null}\n```')
    choice = LLMChooser(llm).choose("two mugs and a plate", SHORT)
    assert choice.objects == (("mug", 2), ("plate", 1)) and choice.replies == 2
    system = server.requests[0]["messages"][0]["content"]
    assert "- mug (" in system and "- bowl (" in system and "giraffe" not in system
    repair = server.requests[1]["messages"][-1]["content"]
    assert "'coffee mug' is not a candidate" in repair and "mug, plate, cup, bowl" in repair


def test_no_suitable_object_is_an_answer(server: FakeOpenAI, llm: ChatBackend) -> None:
    server.script('{"objects": [], "no_match": "the catalog has no giraffe"}')
    choice = LLMChooser(llm).choose("a giraffe", SHORT)
    assert not choice.found and choice.no_match == "the catalog has no giraffe"
    server.script('{"objects": [{"type": "mug"}], "no_match": "x"}', '{"objects": []}', '{"objects": 3}')
    with pytest.raises(PromptError, match="LLM gave no valid choice of objects in 3 replies"):
        LLMChooser(llm).choose("a mug", SHORT)
    problems = [r["messages"][-1]["content"] for r in server.requests[2:4]]
    assert "not both" in problems[0] and "say why none" in problems[1]


def test_describer_repairs_contradictions_and_other_objects(server: FakeOpenAI, llm: ChatBackend) -> None:
    server.script(
        scene([("mug", "mug"), ("plate", "plate")],
              [("left_of", "mug", "plate"), ("right_of", "mug", "plate")]),
        scene([("mug", "mug"), ("bowl", "bowl")], [("left_of", "mug", "bowl")]),
        scene([("mug", "mug"), ("plate", "plate")], [("left_of", "mug", "plate")]))
    desc, replies = LLMDescriber(llm).describe("a mug left of a plate", MUG_PLATE)
    assert replies == 3 and [str(r) for r in desc.relations] == ["left_of(mug, plate)"]
    assert desc.prompt == "a mug left of a plate" and desc.text == "A mug stands left of a plate."
    problems = [r["messages"][-1]["content"] for r in server.requests[1:]]
    assert "relations contradict" in problems[0]
    assert "not chosen: bowl; missing: plate" in problems[1]
    assert '"relations"' in server.requests[0]["messages"][0]["content"]  # the schema is in the prompt


def test_describer_gives_up_after_its_budget(server: FakeOpenAI, llm: ChatBackend) -> None:
    server.script("not json", "[1, 2]", scene([("mug", "mug"), ("plate", "plate")], [("on", "plate", "mug")]))
    with pytest.raises(SceneDescriptionError,
                       match="LLM gave no valid scene description in 3 replies.*mug has no surface"):
        LLMDescriber(llm, max_repairs=2).describe("a plate on a mug", MUG_PLATE)
    assert server.remaining == 0


def test_an_llm_outage_is_not_a_refusal(server: FakeOpenAI, llm: ChatBackend) -> None:
    server.script(Status(503), Status(503))
    with pytest.raises(BackendUnavailableError):
        LLMChooser(llm).choose("a mug", SHORT)


def test_shortlist_holds_the_prompts_and_its_phrases_candidates() -> None:
    text = "organize the breakfast table"
    _, phrases = unknown_phrases(text)
    names = shortlist(retriever().search(text, k=10), phrases, text)
    assert len(names) == len(set(names)) <= 16 and {"bread", "cup"} <= set(names)


def test_a_synthesis_run_with_the_llm(server: FakeOpenAI, llm: ChatBackend, tmp_path: Path) -> None:
    server.script('{"objects": [{"type": "mug"}, {"type": "plate"}], "no_match": null}',
                  scene([("mug", "mug"), ("plate", "plate")], [("left_of", "mug", "plate")]))
    result = synthesize("a mug to the left of a plate", SynthesisConfig(seed=0, attempts=2),
                        DirectorySink(tmp_path), llm=llm)
    assert result.instance.valid and [str(r) for r in result.description.relations] == ["left_of(mug, plate)"]
    written = json.loads((tmp_path / "scene_description.json").read_text())
    assert written["source"] == "llm" and written["replies"] == 1
    assert json.loads((tmp_path / "retrieval.json").read_text())["llm_choice"]["objects"][0]["type"] == "mug"
    funnel = json.loads((tmp_path / "funnel.json").read_text())
    assert funnel[-1]["stage"] == "settle" and funnel[-1]["status"] == "ok"


def test_a_run_with_no_suitable_object_ends_typed(server: FakeOpenAI, llm: ChatBackend,
                                                  tmp_path: Path) -> None:
    server.script('{"objects": [], "no_match": "nothing here is a laptop"}')
    with pytest.raises(PromptError, match="no suitable object for the prompt: nothing here is a laptop"):
        synthesize("a laptop next to a mug", SynthesisConfig(), DirectorySink(tmp_path), llm=llm)
    funnel = json.loads((tmp_path / "funnel.json").read_text())
    assert [(f["stage"], f["status"]) for f in funnel] == [("retrieval", "no_match")]


# -- the LLM answers to what the prompt asks for (issue 52: synthesis never changes the request) --------


def test_what_a_prompt_asks_for() -> None:
    asked = read_prompt("three apples in a bowl, a red mug and no plate")
    assert [(o.type, o.color, o.count) for o in asked.objects] == [("apple", None, 3), ("bowl", None, 1),
                                                                   ("mug", "red", 1)]
    assert [asked.relation_text(r) for r in asked.relations] == ["inside(apple, bowl)"]
    assert [(o.type, o.phrase) for o in asked.negated] == [("plate", "no plate")]


def test_a_choice_that_drops_a_count_or_takes_a_negated_object_is_sent_back(server: FakeOpenAI,
                                                                          llm: ChatBackend) -> None:
    asked = read_prompt("two mugs and a bowl but no plate")
    server.script('{"objects": [{"type": "mug"}, {"type": "bowl"}, {"type": "plate"}], "no_match": null}',
                  '{"objects": [{"type": "mug", "count": 2}, {"type": "bowl"}], "no_match": null}')
    choice = LLMChooser(llm).choose("two mugs and a bowl but no plate", ("plate", "cup"), asked)
    assert choice.objects == (("mug", 2), ("bowl", 1)) and choice.replies == 2
    assert choice.shortlist[:2] == ("mug", "bowl")  # the named types are candidates, first
    repair = server.requests[1]["messages"][-1]["content"]
    assert "asks for 2 x mug; the choice has 1" in repair and "'no plate'; the choice has plate" in repair
    with pytest.raises(PromptError, match="asks for 6 x apple; the LLM chooser takes at most 4"):
        LLMChooser(llm).choose("six apples", SHORT, read_prompt("six apples"))


def test_a_description_that_drops_a_relation_or_holds_a_negated_object_is_refused(
        server: FakeOpenAI, llm: ChatBackend) -> None:
    prompt = "a mug left of a plate, and no red apple"
    choice = Choice((("mug", 1), ("plate", 1), ("apple", 1)), None, ("mug", "plate", "apple"))
    red = {"name": "apple", "type": "apple", "color": "red"}
    bad = json.loads(scene([("mug", "mug"), ("plate", "plate"), ("apple", "apple")],
                           [("right_of", "mug", "plate")]))
    bad["objects"][2] = red
    server.script(*[json.dumps(bad)] * 3)
    with pytest.raises(SceneDescriptionError, match=r"asks for left_of\(mug, plate\).*relates 0 so"):
        LLMDescriber(llm).describe(prompt, choice, read_prompt(prompt))
    system = server.requests[0]["messages"][0]["content"]
    assert "The prompt asks for: 1 x mug; 1 x plate; left_of(mug, plate); no red apple." in system
    assert "'no red apple'; the description has apple" in server.requests[1]["messages"][-1]["content"]
    good = json.loads(scene([("mug", "mug"), ("plate", "plate"), ("apple", "apple")],
                            [("right_of", "plate", "mug")]))  # the same relation, said the other way
    server.script(json.dumps(good))
    desc, _ = LLMDescriber(llm).describe(prompt, choice, read_prompt(prompt))  # a green apple is no red one
    assert [str(r) for r in desc.relations] == ["right_of(plate, mug)"]


def test_a_run_whose_llm_drops_a_count_ends_typed(server: FakeOpenAI, llm: ChatBackend,
                                                  tmp_path: Path) -> None:
    reply = json.loads(scene([("a1", "apple"), ("a2", "apple"), ("plate", "plate")],
                             [("on", "a1", "plate"), ("on", "a2", "plate")]))
    reply["objects"][0]["color"], reply["objects"][1]["color"] = "red", "green"
    server.script('{"objects": [{"type": "apple", "count": 2}, {"type": "plate"}], "no_match": null}',
                  *[json.dumps(reply)] * 3)
    with pytest.raises(SceneDescriptionError, match=r"asks for 2 x red apple \('two red apples'\); the "
                                                    "description has 1"):
        synthesize("two red apples on a plate", SynthesisConfig(), DirectorySink(tmp_path), llm=llm)
    funnel = json.loads((tmp_path / "funnel.json").read_text())
    assert [(f["stage"], f["status"]) for f in funnel] == [("retrieval", "ok"), ("description", "rejected")]
