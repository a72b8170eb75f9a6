"""Any registered atomic task as a Gymnasium environment, for evaluating policies in it.

One episode is one :func:`vcage.tasks.runner.prepare` of the task: the same seed gives the same
scene, settled state and instruction as the scripted expert's episode of that seed, and an action
has the meaning of the expert's recorded action (``Recording.action``): 7 absolute arm joint
position targets and a gripper command in [0, 1] (1 open, 0 closed), applied for one control
period (1 / ``SimConfig.control_hz``). Replaying an expert recording therefore replays the expert.

Observation (a ``Dict``; vectors are float32, quaternions are ``(w, x, y, z)`` with ``w >= 0``,
positions in the world frame in metres):

* ``qpos`` (7,): arm joint positions;
* ``gripper`` (1,): finger opening, the sum of both finger joints in metres (0 to 0.08);
* ``ee_pos`` (3,), ``ee_quat`` (4,): the tool-centre-point pose;
* ``object_poses`` (N, 7): position and quaternion of each object, one row per object in the
  order of ``info["object_names"]`` from :meth:`TaskEnv.reset`: sorted by instance name, so a row
  means the same object in every episode of a task whose names do not depend on the seed (the
  scene's own order may, e.g. when a layout shuffles objects); N is fixed per task;
* ``images`` (only when ``cameras`` are given): camera name -> uint8 RGB (H, W, 3).

Reward is 1.0 on every step whose ``task.evaluate`` reports success, else 0.0. An episode
terminates once success has held for ``task.hold_steps`` consecutive steps (the episode engine's
:class:`~vcage.tasks.engine.Progress`, with the goal the expert's episode is judged by) and is
truncated after ``max_steps`` steps; a terminated episode must be reset before it is stepped again.

A :class:`~vcage.errors.SimulationError` (unstable physics) raised while stepping is **not**
swallowed: it propagates out of :meth:`TaskEnv.step`, since an exploded simulation has no meaningful
observation or reward. The environment must then be reset before it is stepped again.
"""

from __future__ import annotations

import copy
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded

from vcage.config import Randomization, SimConfig
from vcage.errors import ConfigError
from vcage.geometry import mat_to_quat
from vcage.sim.render import Renderer
from vcage.sim.robot import GRIPPER_OPEN
from vcage.sim.world import World
from vcage.tasks import runner
from vcage.tasks.base import AtomicTask
from vcage.tasks.engine import Progress, TaskGoal

__all__ = ["RENDER_CAMERA", "TaskEnv"]

RENDER_CAMERA = "front"  # the camera ``render()`` shows in render mode "rgb_array"
POS_LIMIT = 5.0  # metres from the world origin: observation bound of every position (scene is ~2 m)
JOINT_MARGIN = 0.1  # radians: observed joints may overshoot their (soft) limits slightly
GRIPPER_MARGIN = 0.01  # metres, likewise for the finger opening


class TaskEnv(gym.Env[dict[str, Any], np.ndarray]):
    """The atomic task ``task`` (a name in ``TASKS``) as a Gymnasium environment.

    Args:
        task: registered task name, e.g. ``"stack_blocks_two"``.
        randomization: domain randomisation of each episode's scene (default: ``Randomization()``,
            as the expert's episodes use).
        cameras: cameras rendered into ``obs["images"]`` (e.g. ``("front", "panda/wrist")``).
        image_size: ``(height, width)`` of the camera images and of :meth:`render`.
        max_steps: control steps after which an episode is truncated.
        render_mode: ``None`` or ``"rgb_array"`` (:meth:`render` shows the ``"front"`` camera).

    After :meth:`reset`, ``task`` is the episode's :class:`AtomicTask` instance and ``world`` its
    :class:`World`, e.g. for extra predicates or saving the state.
    """

    metadata: ClassVar[dict[str, Any]] = {  # type: ignore[misc]
        "render_modes": ["rgb_array"],
        "render_fps": SimConfig().control_hz,  # one frame per control step
    }

    def __init__(self, task: str, randomization: Randomization | None = None,
                 cameras: tuple[str, ...] = (), image_size: tuple[int, int] = (128, 128),
                 max_steps: int = 1000, render_mode: str | None = None) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ConfigError(
                f"render_mode {render_mode!r} is not supported; valid: None, "
                f"{', '.join(map(repr, self.metadata['render_modes']))}"
            )
        if int(max_steps) < 1:
            raise ConfigError(f"max_steps must be at least 1, got {max_steps}")
        height, width = (int(v) for v in image_size)
        if height < 1 or width < 1:
            raise ConfigError(f"image_size (height, width) must be positive, got {image_size}")
        self.task_name = task
        self.randomization = Randomization() if randomization is None else randomization
        self.cameras = tuple(cameras)
        self.image_size = (height, width)
        self.max_steps = int(max_steps)
        self.render_mode = render_mode

        # Build the scene once (seed 0) to size the spaces and validate the cameras.
        probe_task, probe = runner.prepare(task, 0, self.randomization)[:2]
        self.hold_steps = probe_task.hold_steps
        self.n_objects = len(probe.object_names)
        self._check_rendering(probe)
        limits = probe.robot.arm_limits.astype(np.float32)
        self._act_low = np.append(limits[:, 0], 0.0).astype(np.float32)
        self._act_high = np.append(limits[:, 1], 1.0).astype(np.float32)
        self.action_space = spaces.Box(self._act_low, self._act_high, dtype=np.float32)
        pose_low = np.tile(np.r_[np.full(3, -POS_LIMIT), np.full(4, -1.0)], (self.n_objects, 1))
        obs: dict[str, spaces.Space[Any]] = {
            "qpos": spaces.Box(limits[:, 0] - JOINT_MARGIN, limits[:, 1] + JOINT_MARGIN,
                               dtype=np.float32),
            "gripper": spaces.Box(-GRIPPER_MARGIN, 2 * GRIPPER_OPEN + GRIPPER_MARGIN, shape=(1,),
                                  dtype=np.float32),
            "ee_pos": spaces.Box(-POS_LIMIT, POS_LIMIT, shape=(3,), dtype=np.float32),
            "ee_quat": spaces.Box(-1.0, 1.0, shape=(4,), dtype=np.float32),
            "object_poses": spaces.Box(pose_low.astype(np.float32), -pose_low.astype(np.float32),
                                       dtype=np.float32),
        }
        if self.cameras:
            obs["images"] = spaces.Dict({
                cam: spaces.Box(0, 255, shape=(height, width, 3), dtype=np.uint8)
                for cam in self.cameras
            })
        self.observation_space = spaces.Dict(obs)

        self.task: AtomicTask | None = None
        self.world: World | None = None
        self.episode_seed: int | None = None
        self.instruction: str | None = None
        self.object_names: tuple[str, ...] = ()  # row order of ``object_poses`` this episode
        self._renderer: Renderer | None = None
        self._elapsed = 0
        self._progress: Progress | None = None
        self._needs_reset = True

    # -- gymnasium API -----------------------------------------------------------------------
    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[dict[str, Any], dict[str, Any]]:
        """Start the episode of ``seed`` (the expert's episode of that seed), or of a seed drawn
        from the environment's generator when ``seed`` is None. ``options`` are ignored."""
        super().reset(seed=seed)
        episode_seed = int(seed) if seed is not None else int(self.np_random.integers(2**31 - 1))
        self._close_renderer()
        task, world, rng = runner.prepare(self.task_name, episode_seed, self.randomization)
        if len(world.object_names) != self.n_objects:
            raise ConfigError(
                f"task {self.task_name!r} has {len(world.object_names)} objects with seed "
                f"{episode_seed} but {self.n_objects} with seed 0; a task's object count must not "
                "depend on the seed for its environment's observation space"
            )
        self.task, self.world, self.episode_seed = task, world, episode_seed
        self.object_names = tuple(sorted(world.object_names))
        self.instruction = task.instruction(rng)  # drawn as run_episode draws it
        if self.cameras or self.render_mode == "rgb_array":
            self._renderer = Renderer(world, width=self.image_size[1], height=self.image_size[0])
        self._elapsed = 0
        self._progress = Progress([TaskGoal(task, world)])
        self._needs_reset = False
        info = {"instruction": self.instruction, "seed": episode_seed,
                "object_names": self.object_names}
        return self._observation(), info

    def step(self, action: np.ndarray) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        """Apply ``action`` (clipped to the action space) for one control period.

        Raises:
            SimulationError: the physics became unstable; reset before stepping again.
            ResetNeeded: :meth:`reset` was not called, the episode terminated, or a previous step
                raised.
            ValueError: the action has the wrong size or is not finite.
        """
        progress = self._progress
        if self._needs_reset or self.world is None or progress is None or progress.finished:
            raise ResetNeeded("call reset() before step() (and after the episode terminated or a "
                              "SimulationError)")
        act = np.asarray(action, dtype=np.float64).reshape(-1)
        if act.shape != self._act_low.shape:
            raise ValueError("action must have 8 values (7 arm joint targets + gripper), "
                             f"got shape {np.shape(action)}")
        if not np.all(np.isfinite(act)):
            raise ValueError(f"action must be finite, got {act}")
        act = np.clip(act, self._act_low, self._act_high)
        world = self.world
        self._needs_reset = True  # until the step completes: a SimulationError leaves it set
        world.step(world.robot.ctrl(act[:7], float(act[7])))  # SimulationError propagates
        self._needs_reset = False
        self._elapsed += 1
        info = copy.deepcopy(progress.update(world))  # the task's on_step, then its evaluate
        success = bool(info["success"])
        terminated = progress.finished
        truncated = self._elapsed >= self.max_steps
        info["is_success"] = terminated
        return self._observation(), 1.0 if success else 0.0, terminated, truncated, info

    def render(self) -> np.ndarray | None:  # type: ignore[override]
        """The ``"front"`` camera's RGB image (H, W, 3) uint8 in render mode ``"rgb_array"``."""
        if self.render_mode is None:
            return None
        if self._renderer is None:
            raise ResetNeeded("call reset() before render()")
        return self._renderer.rgb(RENDER_CAMERA).copy()

    def close(self) -> None:
        """Release the renderer's GL context; safe to call more than once."""
        self._close_renderer()
        super().close()

    # -- helpers -----------------------------------------------------------------------------
    def _observation(self) -> dict[str, Any]:
        world = self.world
        assert world is not None
        robot, data = world.robot, world.data
        pos, mat = robot.tcp_pose(data)
        poses = np.zeros((self.n_objects, 7))
        for i, name in enumerate(self.object_names):
            poses[i, :3] = world.object_pos(name)
            poses[i, 3:] = mat_to_quat(world.object_mat(name))
        obs: dict[str, Any] = {
            "qpos": robot.arm_q(data).astype(np.float32),
            "gripper": np.array([robot.gripper_width(data)], dtype=np.float32),
            "ee_pos": pos.astype(np.float32),
            "ee_quat": mat_to_quat(mat).astype(np.float32),
            "object_poses": poses.astype(np.float32),
        }
        if self.cameras:
            assert self._renderer is not None
            obs["images"] = {cam: self._renderer.rgb(cam).copy() for cam in self.cameras}
        return obs

    def _check_rendering(self, world: World) -> None:
        model = world.model
        names = {model.camera(i).name for i in range(model.ncam)}
        wanted = set(self.cameras) | ({RENDER_CAMERA} if self.render_mode else set())
        unknown = sorted(wanted - names)
        if unknown:
            raise ConfigError(f"unknown camera(s) {unknown}; cameras: {sorted(names)}")
        height, width = self.image_size
        if wanted and (width > model.vis.global_.offwidth or height > model.vis.global_.offheight):
            raise ConfigError(
                f"image_size (height, width) {self.image_size} exceeds the offscreen buffer "
                f"({model.vis.global_.offheight}, {model.vis.global_.offwidth})"
            )

    def _close_renderer(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
