"""Evaluation environments for a dataset's plan: the scenes generation samples, on seeds no
training episode can have, with success and per-subtask progress from the oracle.

:func:`make_env` builds one from the configuration a dataset stores (``meta/vcage.json``, read as
``DatasetReader(root).config``): the same plan, scene sampler (placement, clutter, domain
randomisation) and simulator settings as the generation run that made the dataset.

* **Seeds.** Episode ``k`` of an environment seeded ``s`` places its scene with the seed
  ``2**32 + SeedSequence([s, k, j])`` for the first try ``j`` whose scene places and settles.
  Generation's attempt seeds are below ``2**32`` (:meth:`GenerateConfig.episode_seed`), so no
  evaluation scene is a training scene, for any dataset. ``reset(options={"scene_seed": seed})``
  builds the scene of a given seed instead (an audit: a training episode's seed gives its scene,
  and replaying its actions reproduces its frames). With it, ``"state"`` (a simulator state a
  dataset stores, ``states`` of its episode arrays) and ``"subtask"`` start the episode from that
  state, judged from that subtask on (the earlier ones counted done): can a policy do the second
  subtask of a plan when it is put where a demonstration began it?
* **Observations** are the dataset's feature vectors (:mod:`vcage.pipeline.features`):
  ``observation.state``, ``observation.ee_pose``, ``observation.environment_state``, read as the
  recording reads them during generation.
* **Actions** are one of the dataset's action features (``action``: the default): ``action``, 7
  absolute arm joint targets and a gripper command in [0, 1], held for one control period
  (1 / ``control_hz``); or ``action.ee_pose``, the tool-centre point's target pose (position,
  quaternion w, x, y, z) and the gripper command, which the environment turns into joint targets by
  differential inverse kinematics warm-started from the previous step's targets: replaying a
  demonstration's poses puts the hand on its recorded path, but the elbow, which a pose leaves
  free on a 7-joint arm, can end up elsewhere than the demonstration's (joint angles up to 0.7 rad
  apart), so a policy acting in poses should not observe the joint angles.
* **Success** follows the plan: the subtasks are checked in order, each by the oracle as generation
  checks it (every predicate true on ``HOLD_STEPS`` consecutive control steps; events latched while
  the subtask is the current one). ``info``: ``success``, ``subtasks_done``, ``subtasks``,
  ``progress`` (done / subtasks) and ``scene_seed``. Reward 1 on the step the last subtask
  completes; ``terminated`` then; ``truncated`` after ``max_steps`` steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded

from vcage.errors import ConfigError, PlacementError, SceneError, SimulationError
from vcage.geometry import quat_to_mat
from vcage.pipeline.config import GenerateConfig
from vcage.pipeline.features import (
    ACTION,
    ACTION_EE,
    ACTIONS,
    EE_POSE,
    ENVIRONMENT,
    STATE,
    dataset_features,
    observe,
)
from vcage.pipeline.plan_layout import episode_scene, plan_layout
from vcage.pipeline.rollout import plan_goals
from vcage.planning.schema import Plan
from vcage.scene.instantiate import Instantiator
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.render import Renderer
from vcage.sim.robot import GRIPPER_OPEN
from vcage.sim.world import World
from vcage.skills.ik import IKSolver
from vcage.skills.reachability import reach_map
from vcage.synthesis.errors import SynthesisError
from vcage.tasks.engine import Progress
from vcage.tasks.oracle import Oracle
from vcage.vocabulary import PREDICATES, Kind

EVAL_SEED_BASE = 2**32  # generation's attempt seeds are below: evaluation scenes are never training scenes
STEPS_PER_SUBTASK = 600  # default episode length: 30 s per subtask at 20 Hz (experts take 5-15 s)
POS_LIMIT = 5.0  # metres: bound of every observed position (the scene spans about 2 m)


def eval_seed(base: int, episode: int, attempt: int) -> int:
    """The scene seed of try ``attempt`` of evaluation episode ``episode`` of an env seeded ``base``."""
    return EVAL_SEED_BASE + int(np.random.SeedSequence([base, episode, attempt]).generate_state(1)[0])


def make_env(config: dict[str, Any], *, seed: int = 0, max_steps: int | None = None,
             render_mode: str | None = None, scenes: Sequence[int] | None = None,
             action: str = ACTION) -> GoalEnv:
    """The evaluation environment of a dataset made with ``config`` (its ``meta/vcage.json``
    configuration: ``{"generate": ..., "plan": ...}``); ``scenes`` and ``action``: see
    :class:`GoalEnv`."""
    if not isinstance(config, dict) or not isinstance(config.get("generate"), dict) \
            or not isinstance(config.get("plan"), dict):
        raise ConfigError("an evaluation environment needs the configuration a vcage dataset stores "
                          "(meta/vcage.json: 'generate' and 'plan'); this one has neither")
    return GoalEnv(Plan.model_validate(config["plan"]), GenerateConfig.from_dict(config["generate"]),
                   seed=seed, max_steps=max_steps, render_mode=render_mode, scenes=scenes, action=action)


class GoalEnv(gym.Env[dict[str, np.ndarray], np.ndarray]):
    """The plan ``plan`` in scenes sampled as ``cfg`` samples them, as a Gymnasium environment.

    ``reset()`` without a seed moves to the next evaluation episode; ``reset(seed=s)`` starts the
    episode sequence of seed ``s`` again; ``options={"episode": k}`` goes to episode ``k`` directly
    (so that several processes can share one evaluation's episodes). With ``scenes`` (scene seeds,
    e.g. held-out scenes chosen once for a comparison), episode ``k`` builds
    ``scenes[k % len(scenes)]`` instead. ``action`` names the action feature ``step`` takes
    (``action`` or ``action.ee_pose``, see the module's help). After a reset, ``world`` is the
    episode's :class:`World`.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"]}  # type: ignore[misc]
    episode_option: ClassVar[bool] = True  # reset(options={"episode": k}) starts episode k

    def __init__(self, plan: Plan, cfg: GenerateConfig, *, seed: int = 0, max_steps: int | None = None,
                 render_mode: str | None = None, scenes: Sequence[int] | None = None,
                 action: str = ACTION) -> None:
        if action not in ACTIONS:
            raise ConfigError(f"unknown action {action!r}; valid: {', '.join(ACTIONS)}")
        if render_mode not in (None, "rgb_array"):
            raise ConfigError(f"render_mode {render_mode!r} is not supported; use None or 'rgb_array'")
        if max_steps is not None and (isinstance(max_steps, bool) or not isinstance(max_steps, int)
                                      or max_steps < 1):
            raise ConfigError(f"max_steps must be a positive integer, got {max_steps!r}")
        self.plan, self.cfg, self.render_mode = plan, cfg, render_mode
        self.max_steps = max_steps or STEPS_PER_SUBTASK * len(plan.subtasks)
        self.metadata = {**self.metadata, "render_fps": cfg.sim.control_hz}  # type: ignore[misc]
        self.action_key = action
        self.features = {k: f for k, f in dataset_features(plan).items()
                         if k in (STATE, EE_POSE, ENVIRONMENT, action)}
        self._base, self._episode = int(seed), 0
        self.scenes = [int(x) for x in scenes] if scenes is not None else None
        if self.scenes is not None and (not self.scenes or min(self.scenes) < 0):
            raise ConfigError(f"scenes must be a non-empty list of non-negative scene seeds, got {scenes!r}")
        self._instantiator = Instantiator(cfg.scene, cfg.sim, reach_map())
        self._prebuilt: tuple[int, int, World, int] | None = None  # (base, episode, world, scene seed)
        limits = self._arm_limits()
        n = len(plan.objects)
        pose = np.r_[np.full(3, POS_LIMIT), np.ones(4)].astype(np.float32)
        if action == ACTION_EE:
            self.action_space = spaces.Box(np.append(-pose, 0.0).astype(np.float32),
                                           np.append(pose, 1.0).astype(np.float32), dtype=np.float32)
        else:
            self.action_space = spaces.Box(np.append(limits[:, 0], 0.0).astype(np.float32),
                                           np.append(limits[:, 1], 1.0).astype(np.float32), dtype=np.float32)
        self._ik: IKSolver | None = None
        self._arm_target: np.ndarray | None = None  # the last joint targets (action.ee_pose's IK seed)
        self.observation_space = spaces.Dict({  # type: ignore[assignment]
            STATE: spaces.Box(np.append(limits[:, 0] - 0.1, -0.01).astype(np.float32),
                              np.append(limits[:, 1] + 0.1, 2 * GRIPPER_OPEN + 0.01).astype(np.float32),
                              dtype=np.float32),
            EE_POSE: spaces.Box(-pose, pose, dtype=np.float32),
            ENVIRONMENT: spaces.Box(-np.tile(pose, n), np.tile(pose, n), dtype=np.float32),
        })
        self.world: World | None = None
        self.scene_seed: int | None = None
        self._oracle = Oracle()
        self._progress: Progress | None = None  # the subtasks reached, judged as generation judges them
        self._steps = 0
        self._renderer: Renderer | None = None

    # -- episodes --------------------------------------------------------------------------------
    def _scene(self, seed: int) -> World:
        """The settled world of a scene seed; PlacementError/SceneError/SimulationError if there is none."""
        rng = np.random.default_rng(seed)
        synthesis = self.cfg.synthesis
        scene = self.cfg.synthesized if synthesis is None else episode_scene(self.plan, synthesis, seed)
        layout = plan_layout(self.plan, rng, self.cfg.randomization, self.cfg.scene.clutter, scene=scene)
        spec, stats = self._instantiator.place(layout, rng)
        instance = self._instantiator.realize(spec, stats)
        if not instance.valid:
            assert instance.stability is not None
            raise SceneError(instance.stability.reason())
        return instance.world

    def _arm_limits(self) -> np.ndarray:
        """(7, 2) joint limits of the arm (the robot is the same in every scene): from the scene of
        the first episode, kept for the reset that starts it."""
        world, scene_seed = self._episode_scene(self._base, 0)
        self._prebuilt = (self._base, 0, world, scene_seed)
        return world.robot.arm_limits.astype(np.float32)

    def _episode_scene(self, base: int, episode: int) -> tuple[World, int]:
        """The world of evaluation episode ``episode`` of seed ``base``, and its scene seed."""
        prebuilt, self._prebuilt = self._prebuilt, None
        if prebuilt is not None and prebuilt[:2] == (base, episode):
            return prebuilt[2], prebuilt[3]
        if self.scenes is not None:
            scene_seed = self.scenes[episode % len(self.scenes)]
            return self._scene(scene_seed), scene_seed
        return self._first_scene(base, episode)

    def _first_scene(self, base: int, episode: int) -> tuple[World, int]:
        """The first valid scene of evaluation episode ``episode`` and its seed."""
        reasons = []
        for j in range(self.cfg.max_attempts):
            scene_seed = eval_seed(base, episode, j)
            try:
                return self._scene(scene_seed), scene_seed
            except (PlacementError, SceneError, SimulationError, SynthesisError) as exc:
                reasons.append(str(exc).split(";")[0][:120])
        raise SceneError(f"no valid evaluation scene for episode {episode} in {self.cfg.max_attempts} tries "
                         f"({'; '.join(reasons[:3])}); raise max_attempts or reduce the clutter")

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        if seed is not None:
            self._base, self._episode = int(seed), 0
        options = options or {}
        if options.get("episode") is not None:
            episode = options["episode"]
            if isinstance(episode, bool) or not isinstance(episode, int | np.integer) or episode < 0:
                raise ConfigError(f"options['episode'] must be an episode index >= 0, got {episode!r}")
            self._episode = int(episode)
        subtask = self._start_subtask(options)
        if options.get("scene_seed") is not None:  # an audit: e.g. a training episode's scene
            scene_seed = int(options["scene_seed"])
            world = self._scene(scene_seed)
        else:
            if options.get("state") is not None:
                raise ConfigError("options['state'] is a state of a given scene: pass its "
                                  "options['scene_seed'] too")
            world, scene_seed = self._episode_scene(self._base, self._episode)
            self._episode += 1
        if options.get("state") is not None:
            state = np.asarray(options["state"], dtype=float).reshape(-1)
            size = world.get_state().size
            if state.size != size or not np.isfinite(state).all():
                raise ConfigError(f"options['state'] must be {size} finite numbers (a state the dataset of "
                                  f"this scene stores), got {state.size}")
            world.set_state(state)
        self._close_renderer()
        self.world, self.scene_seed = world, scene_seed
        self._steps = 0
        self._arm_target = world.robot.arm_q(world.data)
        self._progress = Progress(plan_goals(world, self.plan, self._oracle), start=subtask)
        return observe(world, self.plan), self._info()

    def _start_subtask(self, options: dict[str, Any]) -> int:
        subtask = options.get("subtask", 0)
        n = len(self.plan.subtasks)
        if isinstance(subtask, bool) or not isinstance(subtask, int | np.integer) or not 0 <= subtask < n:
            raise ConfigError(f"options['subtask'] must be a subtask index from 0 to {n - 1}, "
                              f"got {subtask!r}")
        if subtask and options.get("state") is None:
            raise ConfigError("options['subtask'] starts an episode from a later subtask, which needs the "
                              "state a demonstration reached there: pass options['state'] too")
        return int(subtask)

    def step(self, action: np.ndarray) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        world, progress = self.world, self._progress
        if world is None or progress is None or progress.finished or self._steps >= self.max_steps:
            raise ResetNeeded("call reset() before step(), and again after an episode ends")
        action = np.asarray(action, dtype=float).reshape(-1)
        if action.shape != (8,) or not np.isfinite(action).all():
            parts = "position, quaternion, gripper" if self.action_key == ACTION_EE \
                else "7 joint targets, gripper"
            raise ValueError(f"an action is 8 finite numbers ({parts}), got {action!r}")
        if self.action_key == ACTION_EE and np.linalg.norm(action[3:7]) < 1e-6:
            raise ValueError(f"the action's quaternion (elements 3-6) is zero, got {action!r}")
        world.step(world.robot.ctrl(self._joint_targets(action), float(action[7])))
        self._steps += 1
        progress.update(world)
        terminated = progress.finished
        truncated = not terminated and self._steps >= self.max_steps
        return observe(world, self.plan), float(terminated), terminated, truncated, self._info()

    def _joint_targets(self, action: np.ndarray) -> np.ndarray:
        """The arm's joint targets of an action: as given, or from the tool pose by IK."""
        if self.action_key != ACTION_EE:
            return action[:7]
        if self._ik is None:
            self._ik = IKSolver(ROBOT_MOUNT)
        assert self._arm_target is not None
        self._arm_target = self._ik.track(action[:3], quat_to_mat(action[3:7]), self._arm_target)
        return self._arm_target

    def holds(self, subtask: int) -> bool:
        """Whether the goal of ``subtask`` holds now: its predicates that are states (an event, such
        as a press, is over once it happened); e.g. is an earlier subtask's work still in place?"""
        if self.world is None:
            raise ResetNeeded("call reset() first")
        return all(self._oracle.value(self.world, p) for p in self.plan.subtasks[subtask].predicates
                   if PREDICATES.get(p.name).kind is not Kind.EVENT)

    def _info(self) -> dict[str, Any]:
        n, done = len(self.plan.subtasks), self._progress.done if self._progress is not None else 0
        return {"success": done == n, "subtasks_done": done, "subtasks": n,
                "progress": done / n, "scene_seed": self.scene_seed}

    # -- rendering -------------------------------------------------------------------------------
    def render(self) -> np.ndarray | None:  # type: ignore[override]
        if self.render_mode != "rgb_array" or self.world is None:
            return None
        if self._renderer is None:
            self._renderer = Renderer(self.world, *self.cfg.render.size, self.cfg.render.mesh_detail)
        return self._renderer.rgb(self.cfg.render.cameras[0]).copy()

    def _close_renderer(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def close(self) -> None:
        self._close_renderer()
        super().close()
