"""Where a run's time goes: every phase measured, none negative, together no more than the total."""

from __future__ import annotations

from pathlib import Path

import pytest

from vcage.config import RenderConfig
from vcage.data import DatasetReader
from vcage.data.layout import RUNS_LOG
from vcage.pipeline.attempt_log import read
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.episode import PHASES, Timing, attempt
from vcage.pipeline.generate import Funnel, generate
from vcage.pipeline.sampling import build_critic
from vcage.planning import make_planner
from vcage.scene.instantiate import SceneConfig

SHORT = "press the bell"
SMALL = {"scene": SceneConfig(clutter=2), "render": RenderConfig(size=(64, 64))}
ATTEMPT_PHASES = ("placement", "compose", "scene_check", "physics", "critic_views", "critic_judge")
OLD_SECONDS = {"physics", "render", "attempts_total"}  # what the runs log held before the phases


def test_timing_adds_every_phase_and_render_is_views_plus_videos() -> None:
    a = Timing(**{name: 1.0 for name in PHASES}, total=20.0)
    b = Timing(physics=2.0, critic_views=0.5, video_render=0.25, total=3.0)
    a.add(b)
    assert a.physics == 3.0 and a.total == 23.0 and a.placement == 1.0
    assert a.render == pytest.approx(1.5 + 1.25)
    assert list(a.phases()) == list(PHASES)


def test_an_attempt_times_its_phases_within_its_total() -> None:
    cfg = GenerateConfig(**SMALL)
    plan = make_planner(cfg.planner).plan(SHORT)
    result = attempt(plan, cfg.episode_seed(0, 0), cfg, build_critic(cfg))
    timing = result.timing
    assert result.accepted
    phases = timing.phases()
    assert all(value >= 0 for value in phases.values())
    for name in ATTEMPT_PHASES:
        assert phases[name] > 0, name
    for name in set(PHASES) - set(ATTEMPT_PHASES):  # the driver's, not the attempt's
        assert phases[name] == 0, name
    assert sum(phases.values()) <= timing.total


def test_the_funnel_and_the_runs_log_carry_every_phase(tmp_path: Path) -> None:
    out = tmp_path / "ds"
    funnel = generate(SHORT, 1, out, GenerateConfig(**SMALL))
    record = read(out / RUNS_LOG)[-1]
    seconds = record["seconds"]
    assert OLD_SECONDS | set(PHASES) <= set(seconds) == set(funnel.to_dict()["seconds"])
    assert all(seconds[name] >= 0 for name in PHASES)
    for name in ("planning", *ATTEMPT_PHASES, "video_render", "features", "encoding", "writing"):
        assert getattr(funnel.timing, name) > 0, name
    # one worker: the phases happen one after another, inside the run's wall time
    assert sum(funnel.timing.phases().values()) <= funnel.wall
    assert sum(seconds[name] for name in PHASES) <= record["wall_seconds"] + 0.01  # rounding
    assert seconds["render"] == pytest.approx(seconds["critic_views"] + seconds["video_render"], abs=0.02)
    attempt_phases = sum(getattr(funnel.timing, name) for name in ATTEMPT_PHASES)
    assert attempt_phases <= funnel.timing.total <= funnel.wall
    # timings stay out of the episode's own files
    extras = DatasetReader(out).extras(0)
    assert not {"timing", "seconds", *PHASES} & set(extras)


def test_an_empty_funnel_reports_zero_seconds() -> None:
    seconds = Funnel().to_dict()["seconds"]
    assert OLD_SECONDS | set(PHASES) <= set(seconds) and not any(seconds.values())
