"""One verification trial of a candidate subtask, in MuJoCo, on a seed.

A trial builds the candidate's scene, moves every free object by one rigid planar offset and turn
drawn from the seed (a few centimetres and degrees: the same scene, seen by a robot that stands a
little differently), settles it and checks it, then gets the skill calls (a template's data, or the
calls a generated program records in the sandbox, run against this trial's object poses), checks
every call, executes them through :class:`~vcage.skills.Skills`, retreats, holds, and judges.

A trial succeeds only if the goal did not already hold before the robot acted (a synthesized scene
is a goal arrangement: its bread may start in its basket), nothing raised, every skill planned, the
oracle's predicates held for
``HOLD_STEPS`` consecutive control steps after settling (``tasks.engine.held``), and the critic
(when one is configured) accepted. Otherwise it records the first failure class: ``scene``, a
sandbox status (``rejected``, ``runtime_error``, ``blocked``, ``timeout``, ...), ``invalid_call``,
``already_holds``, ``skill``, ``physics``, ``error`` (another typed error), ``oracle`` or ``critic``.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import dataclass, field

import mujoco
import numpy as np

from vcage.config import SimConfig
from vcage.critics.base import Critic
from vcage.errors import SimulationError, SubtaskError, VcageError
from vcage.geometry import yaw_of
from vcage.sandbox import Call, Limits, SceneSnapshot, run_program
from vcage.scene.compose import compose
from vcage.scene.spec import SceneSpec
from vcage.scene.stability import StabilityConfig, check_stability
from vcage.sim.render import Renderer
from vcage.sim.world import World
from vcage.skills.base import Skills
from vcage.skills.playback import Player
from vcage.subtasks.calls import SkillCall, api, check_call
from vcage.subtasks.candidates import Candidate
from vcage.subtasks.records import FAILURE, SUCCESS, TrialRecord
from vcage.tasks.engine import PredicateGoal, Step, run
from vcage.tasks.oracle import Oracle
from vcage.tasks.verifier import Verifier


@dataclass(frozen=True)
class TrialConfig:
    """How candidates are verified: trials per candidate, the per-trial jitter, physics, sandbox."""

    trials: int = 10
    jitter_xy: float = 0.02  # metres: the rigid offset of the free objects is uniform in +-this
    jitter_yaw: float = 0.08  # radians: ... and their turn about their centroid
    settle_seconds: float = 0.3
    critic_size: tuple[int, int] = (320, 240)
    sim: SimConfig = field(default_factory=SimConfig)
    limits: Limits = field(default_factory=Limits)

    def __post_init__(self) -> None:
        from vcage.errors import ConfigError

        if isinstance(self.trials, bool) or not isinstance(self.trials, int) or not 1 <= self.trials <= 1000:
            raise ConfigError(f"trials {self.trials!r} must be an integer in [1, 1000]")
        if not (0 <= self.jitter_xy <= 0.1 and 0 <= self.jitter_yaw <= 0.5):
            raise ConfigError(f"jitter ({self.jitter_xy}, {self.jitter_yaw}) must lie in [0, 0.1] m and "
                              "[0, 0.5] rad")


def trial_seed(candidate_id: str, trial: int) -> int:
    """The seed of trial ``trial`` of a candidate: derived from its identity only (31 bits)."""
    digest = hashlib.sha256(f"{candidate_id}/{trial}".encode()).digest()
    return int.from_bytes(digest[:4], "big") & 0x7FFFFFFF


def template_calls(code: str) -> list[Call]:
    """A template's code, which is data: a JSON list of ``{"skill", "args"}`` objects."""
    try:
        data = json.loads(code)
        if not isinstance(data, list) or not data:
            raise ValueError("expected a non-empty list of calls")
        return [Call(str(c["skill"]), dict(c["args"])) for c in data]
    except (ValueError, TypeError, KeyError) as exc:
        raise SubtaskError(f"template code is not a list of skill calls: {exc}") from None


def jitter(world: World, rng: np.random.Generator, xy: float, yaw: float) -> None:
    """Move every free object by one rigid planar offset and turn about their centroid."""
    model, data = world.model, world.data
    free = []
    for inst in world.objects.values():
        jnt = int(model.body_jntadr[inst.body_id])
        if jnt >= 0 and int(model.jnt_type[jnt]) == int(mujoco.mjtJoint.mjJNT_FREE):
            free.append(int(model.jnt_qposadr[jnt]))
    if not free:
        return
    offset, turn = rng.uniform(-xy, xy, size=2), float(rng.uniform(-yaw, yaw))
    centre = np.mean([data.qpos[a:a + 2] for a in free], axis=0)
    c, s = math.cos(turn), math.sin(turn)
    rot = np.array([[c, -s], [s, c]])
    qturn = np.array([math.cos(turn / 2), 0.0, 0.0, math.sin(turn / 2)])
    for a in free:
        data.qpos[a:a + 2] = centre + rot @ (data.qpos[a:a + 2] - centre) + offset
        quat = np.empty(4)
        mujoco.mju_mulQuat(quat, qturn, data.qpos[a + 3:a + 7].copy())
        data.qpos[a + 3:a + 7] = quat
    world.forward()


def snapshot(world: World, spec: SceneSpec) -> SceneSnapshot:
    objects = {}
    for name in world.object_names:
        p = world.object_pos(name)
        objects[name] = (float(p[0]), float(p[1]), float(p[2]), float(yaw_of(world.object_mat(name))))
    return SceneSnapshot(objects, spec.table.x_range, spec.table.y_range, world.table_top())


def run_trial(cand: Candidate, spec: SceneSpec, trial: int, critic: Critic | None,
              cfg: TrialConfig = TrialConfig(), identity: str | None = None) -> TrialRecord:
    """Trial ``trial`` of ``cand`` in ``spec``, seeded by :func:`trial_seed` from the candidate's id
    (or from ``identity``: programs compared on one task share their seeds)."""
    seed = trial_seed(identity or cand.id, trial)
    t0 = time.perf_counter()
    failure, detail = _run(cand, spec, seed, critic, cfg)
    return TrialRecord(trial, seed, FAILURE if failure else SUCCESS, failure, detail[:500],
                       time.perf_counter() - t0)


def _run(cand: Candidate, spec: SceneSpec, seed: int, critic: Critic | None,
         cfg: TrialConfig) -> tuple[str | None, str]:
    try:
        world = compose(spec, cfg.sim).make_world(cfg.sim)
    except VcageError as exc:  # e.g. a scene file naming an unknown object type
        return "scene", f"{type(exc).__name__}: {exc}"
    jitter(world, np.random.default_rng(seed), cfg.jitter_xy, cfg.jitter_yaw)
    report = check_stability(world, StabilityConfig(settle_seconds=cfg.settle_seconds))
    if not report.ok:
        return "scene", report.reason()
    try:
        calls = _calls(cand, spec, world, cfg)
    except _Failed as exc:
        return exc.kind, exc.detail
    renderer = (Renderer(world, *cfg.critic_size) if critic is not None and critic.needs_views else None)
    try:
        return _execute(cand, calls, world, critic, renderer)
    except SimulationError as exc:
        return "physics", str(exc)
    except VcageError as exc:  # anything else a skill raised on purpose: recorded, not fatal to the run
        return "error", f"{type(exc).__name__}: {exc}"
    finally:
        if renderer is not None:
            renderer.close()


class _Failed(Exception):  # noqa: N818 - a trial outcome, not an error
    def __init__(self, kind: str, detail: str) -> None:
        super().__init__(detail)
        self.kind, self.detail = kind, detail


def _calls(cand: Candidate, spec: SceneSpec, world: World, cfg: TrialConfig) -> list[SkillCall]:
    if cand.is_program:
        result = run_program(cand.code, api(), snapshot(world, spec), cfg.limits)
        if not result.ok:
            raise _Failed(result.status, result.describe())
        raw = list(result.calls)
        if not raw:
            raise _Failed("invalid_call", "the program called no skill")
    else:
        try:
            raw = template_calls(cand.code)
        except SubtaskError as exc:
            raise _Failed("invalid_call", str(exc)) from None
    try:
        return [check_call(c, spec) for c in raw]
    except SubtaskError as exc:
        raise _Failed("invalid_call", str(exc)) from None


def _execute(cand: Candidate, calls: list[SkillCall], world: World, critic: Critic | None,
             renderer: Renderer | None) -> tuple[str | None, str]:
    skills = Skills(world, Player(world, record_states=renderer is not None))
    oracle = Oracle()
    if all(oracle.check(world, cand.predicates).values()):  # events are never true before begin()
        return "already_holds", "the goal held before the robot acted: nothing to verify in this scene"
    subtask = cand.subtask()

    def act(skills: Skills) -> None:
        for call in calls:
            skills.do(call.skill, **call.kwargs)
        if calls[-1].skill != "retreat":
            skills.do("retreat")  # back home: the views after show the scene unobstructed

    verifier = (Verifier(world, [subtask], critic, renderer, skills.player.recording)
                if critic is not None else None)
    step = Step(subtask.skill, subtask.description, act, PredicateGoal(oracle, world, tuple(cand.predicates)))
    outcome = run(skills, [step], verifier, judge_unmet=False).outcomes[0]
    if outcome.skill_error is not None:
        return "skill", outcome.skill_error
    if not outcome.oracle_success:
        return "oracle", "predicates do not hold: " + ", ".join(k for k, v in outcome.oracle.items() if not v)
    if outcome.verdict is None:
        return None, "oracle predicates held"
    return (None if outcome.verdict["accept"] else "critic"), str(outcome.verdict["reason"])
