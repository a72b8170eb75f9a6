"""The per-frame features of a generated dataset, and how each is read off a world.

The same functions make the dataset's frames (from the recording and the simulator states of an
accepted attempt), back-fill an older dataset (from its stored states), and make the observations
of the evaluation environment (:mod:`vcage.pipeline.evaluation`), so a policy sees at evaluation
exactly what it was trained on:

* ``observation.state`` (8): the 7 arm joints and the finger opening (metres);
* ``observation.ee_pose`` (7): the tool-centre point, position and quaternion (w, x, y, z);
* ``observation.environment_state`` (7 per object): pose of each of the plan's objects, in the
  order the plan lists them (LeRobot's name for low-dimensional environment state), from the
  kinematics of the frame's simulator state; distractors are not included;
* ``subtask_index`` (1, int64): the subtask of the plan the frame belongs to (0-based);
* ``action`` (8): the 7 arm joint targets and the gripper command (1 open, 0 closed);
* ``action.ee_pose`` (8): the same action in the tool's space: the tool-centre-point pose the joint
  targets put the hand at (forward kinematics: position and quaternion ``w >= 0``) and the gripper
  command. The evaluation environment takes either (:class:`vcage.pipeline.evaluation.GoalEnv`'s
  ``action``); a policy that predicts poses generalises over object positions more directly than
  one that predicts joint angles.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from vcage.data import Feature
from vcage.geometry import mat_to_quat
from vcage.planning.schema import Plan
from vcage.sim.world import World

JOINTS = [f"joint{i}" for i in range(1, 8)]
POSE = ("x", "y", "z", "qw", "qx", "qy", "qz")
STATE, EE_POSE, ENVIRONMENT = "observation.state", "observation.ee_pose", "observation.environment_state"
SUBTASK, ACTION, ACTION_EE = "subtask_index", "action", "action.ee_pose"
ACTIONS = (ACTION, ACTION_EE)


def objects_of(plan: Plan) -> list[str]:
    """The objects whose poses make the environment state, in its order: the plan's objects."""
    return [o.name for o in plan.objects]


def pose_slice(plan: Plan, name: str) -> slice:
    """Where object ``name``'s pose (x, y, z, qw, qx, qy, qz) lies in the environment state of ``plan``."""
    at = objects_of(plan).index(name) * len(POSE)
    return slice(at, at + len(POSE))


def dataset_features(plan: Plan) -> dict[str, Feature]:
    """The per-frame vector features of a dataset made for ``plan`` (cameras come on top)."""
    return {
        STATE: Feature("float32", (8,), names=[*JOINTS, "gripper_width"]),
        EE_POSE: Feature("float32", (7,), names=list(POSE)),
        ENVIRONMENT: Feature("float32", (7 * len(plan.objects),),
                             names=[f"{name}.{c}" for name in objects_of(plan) for c in POSE]),
        SUBTASK: Feature("int64", (1,), names=["subtask"]),
        ACTION: Feature("float32", (8,), names=[*JOINTS, "gripper"]),
        ACTION_EE: Feature("float32", (8,), names=[*POSE, "gripper"]),
    }


def environment_states(world: World, plan: Plan, states: np.ndarray) -> np.ndarray:
    """(T, 7 * objects) environment state of each recorded simulator state."""
    names = objects_of(plan)
    return np.stack([world.object_poses(names, state).reshape(-1) for state in states]).astype(np.float32)


def ee_actions(world: World, actions: np.ndarray) -> np.ndarray:
    """(T, 8) ``action.ee_pose`` of (T, 8) joint actions: where each row's joint targets put the
    tool-centre point, and its gripper command. Computed from the actions as the dataset stores them
    (float32), so generation and back-fill write the same values."""
    actions = np.asarray(actions, dtype=np.float32).astype(float).reshape(len(actions), -1)
    return np.column_stack([world.tcp_poses(actions[:, :7]), actions[:, 7]]).astype(np.float32)


def subtask_indices(bounds: Sequence[Sequence[int]], length: int) -> np.ndarray:
    """(T, 1) subtask of each frame from the subtasks' ``[start, end)`` frame ranges (frames before
    the first belong to it, frames after the last to the last)."""
    out = np.zeros((length, 1), dtype=np.int64)
    for i, (start, _end) in enumerate(bounds):
        out[max(0, int(start)):] = i
    return out


def frames_of(recording: dict[str, np.ndarray], env_state: np.ndarray, subtasks: np.ndarray,
              ee_action: np.ndarray) -> dict[str, Any]:
    """The dataset frames of an accepted attempt from its recording arrays
    (:meth:`vcage.skills.playback.Recording.arrays`), with the features computed from its world
    (:func:`environment_states`, :func:`subtask_indices`, :func:`ee_actions`)."""
    return {
        STATE: np.column_stack([recording["qpos"], recording["gripper"]]).astype(np.float32),
        EE_POSE: np.column_stack([recording["ee_pos"], recording["ee_quat"]]).astype(np.float32),
        ENVIRONMENT: env_state,
        SUBTASK: subtasks,
        ACTION: recording["action"].astype(np.float32),
        ACTION_EE: ee_action,
    }


def observe(world: World, plan: Plan) -> dict[str, np.ndarray]:
    """The observation features of the world now, as the recording reads them at a control step
    (:class:`vcage.skills.playback.Player`): joints, finger opening and tool pose from the data,
    the objects' poses from the kinematics of the current joint positions."""
    robot, data = world.robot, world.data
    pos, mat = robot.tcp_pose(data)
    return {
        STATE: np.append(robot.arm_q(data), robot.gripper_width(data)).astype(np.float32),
        EE_POSE: np.concatenate([pos, mat_to_quat(mat)]).astype(np.float32),
        ENVIRONMENT: world.object_poses(objects_of(plan)).reshape(-1).astype(np.float32),
    }
