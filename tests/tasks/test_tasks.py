from __future__ import annotations

import numpy as np
import pytest

from vcage.config import Randomization
from vcage.errors import RegistryError
from vcage.scene.instantiate import SceneConfig
from vcage.scene.placement import PlacementStats
from vcage.scene.spec import SceneSpec
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Player
from vcage.tasks import TASKS, AtomicTask, make_task, place_scene, run_episode
from vcage.tasks.engine import held

ALL_TASKS = TASKS.names()


def _place(task: AtomicTask, seed: int, rand: Randomization,
           scene: SceneConfig | None = None) -> tuple[SceneSpec, PlacementStats]:
    """Lay out and place ``task``'s scene as an episode of ``seed`` does (no physics)."""
    _, stats = place_scene(task, np.random.default_rng(seed), rand, scene)
    assert task.spec is not None
    return task.spec, stats


def test_library_has_at_least_fifteen_tasks() -> None:
    assert len(ALL_TASKS) >= 15


def test_held_needs_consecutive_steps_not_one_frame(world: World) -> None:
    calls = iter(range(100))

    def check() -> dict[str, bool]:
        i = next(calls)
        return {"steady": True, "flicker": i % 2 == 0, "late": i >= 4, "too_late": i >= 5}

    skills = Skills(world, Player(world))
    holds, last = held(skills, check, steps=4)
    assert holds == {"steady": True, "flicker": False, "late": True, "too_late": False}
    assert last == {"steady": True, "flicker": False, "late": True, "too_late": True}
    assert len(skills.player.recording) == 8  # 2 * steps control steps were recorded


def test_unknown_task_lists_valid_names() -> None:
    with pytest.raises(RegistryError, match="valid names: .*stack_blocks_two"):
        make_task("fold_laundry")


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL_TASKS)
def test_expert_succeeds_without_randomization(name: str) -> None:
    result = run_episode(name, seed=0, rand=Randomization.off(), record=False)
    assert result.success, (result.info, result.skill_error)
    assert result.instruction and "{" not in result.instruction


@pytest.mark.parametrize("name", ["stack_blocks_two", "click_bell", "place_a2b_left"])
def test_same_seed_same_episode(name: str) -> None:
    a = run_episode(name, seed=7)
    b = run_episode(name, seed=7)
    assert a.spec == b.spec and a.instruction == b.instruction
    np.testing.assert_array_equal(a.initial_state, b.initial_state)
    np.testing.assert_array_equal(a.recording.arrays()["qpos"], b.recording.arrays()["qpos"])
    c = run_episode(name, seed=8)
    assert c.spec != a.spec


def test_randomization_switch_turns_everything_off() -> None:
    off = [_place(make_task("place_mouse_pad"), s, Randomization.off())[0] for s in range(3)]
    assert off[0] == off[1] == off[2]
    on = [_place(make_task("place_mouse_pad"), s, Randomization())[0] for s in range(3)]
    assert on[0] != on[1]
    assert len({o.table.height for o in on}) == 3 and len({o.light for o in on}) == 3


def test_press_success_is_latched_not_instantaneous() -> None:
    result = run_episode("click_bell", seed=0, rand=Randomization.off())
    # the button springs back after the press, yet the latched press counts
    assert result.success and result.info["pressed(bell)"]
    assert result.world.data.joint("bell/button").qpos[0] > -0.002


@pytest.mark.parametrize("name", ALL_TASKS)
def test_task_scenes_go_through_context_aware_placement(name: str) -> None:
    from vcage.scene.placement.geometry import footprint

    task = make_task(name)
    spec, stats = _place(task, 5, Randomization(), SceneConfig(clutter=6))
    assert stats.method == "context"
    clutter = [o for o in spec.objects if o.name.startswith("clutter")]
    assert len(clutter) == 6
    shapes = {o.name: footprint(o.type, o.scale, o.yaw, o.xy) for o in spec.objects}
    names = list(shapes)
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            assert not shapes[a].intersects(shapes[b]), (a, b)
    for zone in task.reserved:
        import shapely

        assert not any(shapely.box(*zone.region.bounds).intersects(shapes[o.name]) for o in clutter)


@pytest.mark.parametrize("name", ["stack_blocks_three", "place_bread_basket", "click_alarmclock"])
def test_experts_work_in_clutter(name: str) -> None:
    result = run_episode(name, seed=2, record=False, scene=SceneConfig(clutter=8))
    assert result.success, (result.info, result.skill_error)
    assert sum(o.name.startswith("clutter") for o in result.spec.objects) == 8


def test_naive_task_placement_is_available_for_comparison() -> None:
    _, stats = _place(make_task("stack_blocks_two"), 0, Randomization(), SceneConfig("naive", clutter=4))
    assert stats.method == "naive"
    with pytest.raises(RegistryError, match="context, naive, rejection"):
        SceneConfig("magic")


def test_invalid_task_scenes_are_rejected_with_the_reason() -> None:
    from vcage.errors import UnstableSceneError
    from vcage.tasks import prepare

    crowded = SceneConfig("naive", clutter=25)
    with pytest.raises(UnstableSceneError, match="stack_blocks_two .*naive placement.*interpenetrating"):
        prepare("stack_blocks_two", 0, Randomization(), scene=crowded)
    # Vanilla mode skips the check: the same scene is built and settled without complaint
    prepare("stack_blocks_two", 0, Randomization(), scene=SceneConfig("naive", clutter=25, check=False))


def test_every_library_module_registers_the_task_named_after_it() -> None:
    """A new task is one file in vcage/tasks/library: nothing else needs an edit."""
    import importlib

    from vcage.envs import builtin_task_names
    from vcage.tasks.library import MODULES

    assert list(MODULES) == builtin_task_names()
    for module in MODULES:
        cls = TASKS.get(module)
        assert cls.__module__.startswith("vcage.tasks.library.")
        assert any(cls is getattr(importlib.import_module(f"vcage.tasks.library.{module}"), n, None)
                   for n in dir(importlib.import_module(f"vcage.tasks.library.{module}")))


def test_atomic_success_is_judged_by_the_oracle_in_the_vocabulary() -> None:
    result = run_episode("place_mouse_pad", seed=0, rand=Randomization.off(), record=False)
    assert result.success
    assert set(result.info) == {"success", "on(mouse, pad)", "released(mouse)"}
    assert all(result.info.values())
