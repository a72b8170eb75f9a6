"""Offline planner (sequences, goal paraphrases, refusals) and the LLM planner over real HTTP."""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from backends.fake_openai import Delay, FakeOpenAI
from vcage.backends import BackendConfig, make_backend
from vcage.errors import BackendTimeout, ConfigError, PlanningError
from vcage.planning import PLANNERS, LLMPlanner, OfflinePlanner, make_planner
from vcage.planning.goals import GOALS
from vcage.planning.schema import Plan

OFFLINE = OfflinePlanner()


def test_goal_library_has_twenty_goals_of_three_to_six_subtasks() -> None:
    assert len(GOALS) >= 20
    lengths = []
    for goal in GOALS:
        plan = goal.plan(goal.phrasings[0])
        assert 3 <= len(plan.subtasks) <= 6, goal.name
        assert all(st.predicates for st in plan.subtasks)
        lengths.append(len(plan.subtasks))
    assert sum(n >= 4 for n in lengths) >= 4 and max(lengths) == 6


def test_goal_subtasks_use_only_what_the_image_critic_judges() -> None:
    from vcage.critics.image import IMAGE_CHECKS

    used = {p.name for goal in GOALS for st in goal.subtasks for p in st.predicates}
    assert used <= set(IMAGE_CHECKS.names())


@pytest.mark.parametrize("goal, first, then", [
    ("nest_and_stow", "small", "large"),  # the nested bowls are moved together
    ("raise_a_skyscraper", "second", "third"),  # each block goes on the one placed before
    ("weigh_the_fruit", "apple", "orange"),  # the scale is free again only after the apple left it
])
def test_goals_whose_subtasks_depend_on_each_other(goal: str, first: str, then: str) -> None:
    plan = next(g for g in GOALS if g.name == goal).plan(goal)
    moved = [st.args.get("obj") for st in plan.subtasks]
    targets = [st.args.get("target") for st in plan.subtasks]
    assert first in moved and then in moved
    i = moved.index(first)
    later = moved[i + 1:] + targets[i + 1:]
    assert first in later or targets[i] in later  # a later subtask acts on what this one built


@pytest.mark.parametrize("text, goal", [
    ("get ready for work", "get_ready_for_work"),
    ("could you get my workspace ready for the day", "get_ready_for_work"),
    ("I would like breakfast", "prepare_breakfast"),
    ("clean up my office", "tidy_the_desk"),
    ("sort the cubes by color", "sort_blocks_by_colour"),
    ("make a pile of blocks", "build_a_tower"),
    ("switch everything off before leaving", "shut_down_for_the_night"),
    ("serve some coffee", "serve_tea"),
    ("lay the dinner table", "set_the_table"),
    ("Tidy up the kitchen counter, please!", "tidy_the_kitchen"),
])
def test_paraphrases_reach_their_goal(text: str, goal: str) -> None:
    plan = OFFLINE.plan(text)
    assert plan.goal == goal and plan.instruction == text


def test_explicit_sequences_become_subtasks() -> None:
    plan = OFFLINE.plan("Put the mouse on the pad, then press the bell")
    assert [st.skill for st in plan.subtasks] == ["pick_and_place", "press"]
    assert {o.type for o in plan.objects} == {"mouse", "mouse_pad", "bell"}
    assert [str(p) for p in plan.subtasks[0].predicates] == ["on(mouse, mouse_pad)", "released(mouse)"]
    three = OFFLINE.plan("put the red block on the blue block, put the green block on the red block "
                         "and then ring the bell")
    assert [o.name for o in three.objects] == ["red_block", "blue_block", "green_block", "bell"]
    assert three.subtasks[1].args == {"obj": "green_block", "target": "red_block"}
    nested = OFFLINE.plan("put the small bowl in the other bowl")
    assert nested.subtasks[0].args["obj"] != nested.subtasks[0].args["target"]
    assert str(nested.subtasks[0].predicates[0]).startswith("inside(")


@pytest.mark.parametrize("text, message", [
    ("", "empty or unintelligible"),
    ("?!", "empty or unintelligible"),
    ("fly to the moon", "cannot ground 'fly to the moon'.*LLM planner"),
    ("put the unicorn on the pad", "unknown object 'the unicorn'.*known objects: .*mouse pad"),
    ("put the purple mouse on the pad", "no purple mouse"),
    ("put the mouse on the apple", "nothing can be put on or in the apple"),
    ("press the apple", "cannot be pressed.*pressable: "),
])
def test_offline_refusals_say_what_it_can_do(text: str, message: str) -> None:
    with pytest.raises(PlanningError, match=message):
        OFFLINE.plan(text)


def test_plan_schema_rejects_bad_plans() -> None:
    good = GOALS[0].plan("x").model_dump()
    Plan.model_validate(good)
    for path, value, message in [
        (("objects", 0, "type"), "unicorn", "unknown object type 'unicorn'"),
        (("subtasks", 0, "skill"), "teleport", "unknown skill 'teleport'"),
        (("subtasks", 0, "args"), {"obj": "ghost"}, "unknown object"),
        (("subtasks", 0, "args"), {"obj": "clock", "speed": 3}, "has no argument"),
        (("subtasks", 0, "predicates"), [{"name": "on", "args": ["clock"]}], "takes 2..2 objects"),
        (("subtasks", 1, "args"), {"obj": "phone", "target": "stand", "placement": "roof"},
         r"names placement 'roof' of 'stand'; its placements: \['slot'\]"),
    ]:
        bad = json.loads(json.dumps(good, default=list))
        node = bad
        for key in path[:-1]:
            node = node[key]
        node[path[-1]] = value
        with pytest.raises(ValueError, match=message):
            Plan.model_validate(bad)


def test_plan_schema_refuses_drawers_used_out_of_order_or_on_objects_without_one() -> None:
    stow = next(g for g in GOALS if g.name == "stow_the_soap").plan("stow the soap").model_dump()
    Plan.model_validate(stow)  # open, put in, shut
    shut_first = {**stow, "subtasks": [stow["subtasks"][2], stow["subtasks"][1]]}
    with pytest.raises(ValueError, match="into the drawer of 'cabinet' while it is shut; open it first"):
        Plan.model_validate(shut_first)
    never_opened = {**stow, "subtasks": [stow["subtasks"][1]]}
    with pytest.raises(ValueError, match="while it is shut"):
        Plan.model_validate(never_opened)
    soap_drawer = json.loads(json.dumps(stow))
    soap_drawer["subtasks"][0]["args"]["obj"] = "soap"
    with pytest.raises(ValueError, match="names 'soap', a soap, which has no drawer"):
        Plan.model_validate(soap_drawer)


def test_plan_schema_refuses_to_turn_an_object_without_a_face_towards_the_robot() -> None:
    desk = next(g for g in GOALS if g.name == "open_the_front_desk").plan("open the front desk").model_dump()
    Plan.model_validate(desk)  # the board has a face: its code
    bell_turned = json.loads(json.dumps(desk))
    bell_turned["subtasks"][0]["args"]["obj"] = "bell"
    with pytest.raises(ValueError, match="turns 'bell', a bell, to face the robot, but it has no face"):
        Plan.model_validate(bell_turned)
    bell_checked = json.loads(json.dumps(desk))
    bell_checked["subtasks"][2]["predicates"].append({"name": "facing", "args": ["bell"]})
    with pytest.raises(ValueError, match="subtask 2 \\(press\\) turns 'bell'"):
        Plan.model_validate(bell_checked)


def test_plan_schema_refuses_to_hang_what_has_no_loop_or_on_what_has_no_hook() -> None:
    corner = next(g for g in GOALS if g.name == "tidy_the_coffee_corner").plan("tidy the coffee corner")
    dumped = corner.model_dump()
    Plan.model_validate(dumped)  # the mug's handle on the rack's peg
    cup_hung = json.loads(json.dumps(dumped))
    cup_hung["subtasks"][0]["args"]["obj"] = "cup"
    with pytest.raises(ValueError, match="hangs 'cup' on 'rack', but 'cup', a cup, has no loop"):
        Plan.model_validate(cup_hung)
    on_bell = json.loads(json.dumps(dumped))
    on_bell["subtasks"][0]["predicates"][0]["args"] = ["mug", "bell"]
    with pytest.raises(ValueError, match="'bell', a bell, has no hook; objects with one: \\['mug_rack'\\]"):
        Plan.model_validate(on_bell)


# -- LLM planner against a local OpenAI-protocol server ------------------------------------------

@pytest.fixture()
def server() -> Iterator[FakeOpenAI]:
    with FakeOpenAI() as srv:
        yield srv


def _planner(server: FakeOpenAI, **kw: float) -> LLMPlanner:
    cfg = BackendConfig(base_url=server.base_url, model="fake-planner", timeout=kw.get("timeout", 5.0),
                        max_retries=int(kw.get("retries", 0)), backoff=0.01)
    return LLMPlanner(make_backend("openai", cfg))


VALID = {"objects": [{"name": "mouse", "type": "mouse"}, {"name": "pad", "type": "mouse_pad"}],
         "subtasks": [{"skill": "pick_and_place", "args": {"obj": "mouse", "target": "pad"},
                       "description": "the mouse lies on the pad",
                       "predicates": [{"name": "on", "args": ["mouse", "pad"]}]}]}


def test_llm_planner_valid_reply(server: FakeOpenAI) -> None:
    server.script(json.dumps(VALID))
    plan = _planner(server).plan("tidy the mouse away")
    assert plan.instruction == "tidy the mouse away" and plan.subtasks[0].args["target"] == "pad"
    request = server.requests[0]
    assert request["model"] == "fake-planner" and request["response_format"] == {"type": "json_object"}
    prompt = request["messages"][0]["content"]
    assert "pick_and_place(obj" in prompt and "mouse_pad" in prompt and '"subtasks"' in prompt


def test_llm_planner_repairs_malformed_json_and_schema_violations(server: FakeOpenAI) -> None:
    bad_type = dict(VALID, objects=[{"name": "mouse", "type": "hamster"},
                                    {"name": "pad", "type": "mouse_pad"}])
    server.script("```json\n{not json", json.dumps(bad_type), "```json\n" + json.dumps(VALID) + "\n```")
    plan = _planner(server).plan("put the mouse on its pad")
    assert plan.objects[0].type == "mouse" and len(server.requests) == 3
    repair1 = server.requests[1]["messages"][-1]["content"]
    repair2 = server.requests[2]["messages"][-1]["content"]
    assert "not valid JSON" in repair1 and "unknown object type 'hamster'" in repair2


def test_llm_planner_gives_up_after_bounded_repairs(server: FakeOpenAI) -> None:
    server.script("[]", "{}", '{"objects": []}')
    with pytest.raises(PlanningError, match="no valid plan .* after 3 replies"):
        _planner(server).plan("put the mouse on its pad")
    assert len(server.requests) == 3


def test_llm_planner_timeout_is_typed(server: FakeOpenAI) -> None:
    server.script(Delay(2.0, then=json.dumps(VALID)))
    with pytest.raises(BackendTimeout):
        _planner(server, timeout=0.2).plan("put the mouse on its pad")


def test_llm_planner_needs_a_model_name(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("VCAGE_LLM_MODEL", raising=False)
    with pytest.raises(ConfigError, match="VCAGE_LLM_MODEL"):
        make_planner("llm")
    assert PLANNERS.names() == ["llm", "offline"]


def test_llm_plan_that_drops_a_named_object_is_sent_back_then_refused(server: FakeOpenAI) -> None:
    instruction = "put the mouse on the pad, then ring the bell"
    with_bell = dict(VALID, objects=[*VALID["objects"], {"name": "bell", "type": "bell"}],
                     subtasks=[*VALID["subtasks"], {"skill": "press", "args": {"obj": "bell"},
                                                    "description": "the bell was rung",
                                                    "predicates": [{"name": "pressed", "args": ["bell"]}]}])
    server.script(json.dumps(VALID), json.dumps(with_bell))
    plan = _planner(server).plan(instruction)
    assert [o.type for o in plan.objects] == ["mouse", "mouse_pad", "bell"]
    repair = server.requests[1]["messages"][-1]["content"]
    assert "names bell" in repair and "no such object" in repair
    server.script(*([json.dumps(VALID)] * 3))
    with pytest.raises(PlanningError, match="names bell"):
        _planner(server).plan(instruction)
