"""The Franka Panda arm and hand, built from the asset files shipped by ``gymnasium-robotics``.

Only the asset files are used (Apache-2.0): the kinematic chain, meshes and actuators are read,
their mesh paths made absolute, and the result is edited with ``MjSpec``: gravity compensation on
every link, a tool-centre-point site between the finger pads, and a wrist camera.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import mujoco
import numpy as np

from vcage.geometry import look_at_quat

PREFIX = "panda/"  # every robot element is named with this prefix once attached to a scene
ARM_JOINTS = tuple(f"{PREFIX}robot:panda0_joint{i}" for i in range(1, 8))
FINGER_JOINTS = (f"{PREFIX}robot:panda0_finger_joint1", f"{PREFIX}robot:panda0_finger_joint2")
ARM_ACTUATORS = tuple(f"{PREFIX}panda0_joint{i}" for i in range(1, 8))
FINGER_ACTUATORS = (f"{PREFIX}r_gripper_finger_joint", f"{PREFIX}l_gripper_finger_joint")
HAND_BODY = f"{PREFIX}panda0_link7"
FINGER_BODIES = (f"{PREFIX}panda0_leftfinger", f"{PREFIX}panda0_rightfinger")
TCP_SITE = f"{PREFIX}tcp"
BASE_BODY = f"{PREFIX}panda0_link0"
WRIST_CAMERA = f"{PREFIX}wrist"
GRIPPER_OPEN = 0.04  # metres per finger
# The box bounding the open fingers' collision geoms in the TCP frame (from the geoms' bounding
# boxes in the model; a test keeps these true): it reaches FINGER_OUTER from the TCP along the
# closing axis and FINGER_HALF_WIDTH across it. A neighbour inside it blocks a grasp's descent.
FINGER_OUTER = 0.070
FINGER_HALF_WIDTH = 0.022
FINGER_THICKNESS = FINGER_OUTER - GRIPPER_OPEN  # beyond the pad: closed on w, the box reaches w/2 + this
# A comfortable home posture with the hand pointing down above the table.
HOME_QPOS = np.array([0.0, -0.5, 0.0, -2.4, 0.0, 0.35, 0.0])
# Distance from link7's origin to the point midway between the finger pads.
TCP_OFFSET = 0.225


def franka_asset_dir() -> Path:
    import importlib.util

    spec = importlib.util.find_spec("gymnasium_robotics")
    if spec is None or spec.origin is None:
        from vcage.errors import SceneError

        raise SceneError("gymnasium-robotics is not installed; run `pip install gymnasium-robotics`")
    return Path(spec.origin).parent / "envs" / "assets" / "kitchen_franka" / "franka_assets"


def _fragment(path: Path) -> str:
    text = path.read_text()
    text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
    return text.replace("<mujocoinclude>", "").replace("</mujocoinclude>", "")


@cache
def _panda_xml() -> str:
    root = franka_asset_dir()
    assets = _fragment(root / "assets.xml")
    assets = re.sub(r'<compiler[^>]*/>', "", assets)
    assets = re.sub(r'<option[^>]*/>', "", assets)
    assets = re.sub(r"<size[^>]*/>", "", assets)
    chain = _fragment(root / "chain.xml")
    actuators = _fragment(root / "actuator.xml")
    # Actuator user data is unused; dropping it lets the spec attach without a size conflict.
    assets, actuators = (re.sub(r"\suser=(['\"])[^'\"]*\1", "", t) for t in (assets, actuators))
    return (
        f'<mujoco model="panda"><compiler angle="radian" meshdir="{root / "meshes"}"/>'
        f"{assets}<worldbody>{chain}</worldbody>{actuators}</mujoco>"
    )


@dataclass(frozen=True)
class RobotSpecOptions:
    wrist_camera: bool = True
    gravity_compensation: bool = True


def panda_spec(options: RobotSpecOptions = RobotSpecOptions()) -> mujoco.MjSpec:
    """A fresh ``MjSpec`` of the Panda with hand, ready to attach to a scene."""
    spec = mujoco.MjSpec.from_string(_panda_xml())
    for body in spec.bodies:
        if options.gravity_compensation and body.name:
            body.gravcomp = 1.0
    hand = spec.body(HAND_BODY.removeprefix(PREFIX))
    hand.add_site(name="tcp", pos=[0, 0, TCP_OFFSET], size=[0.005, 0, 0], rgba=[1, 0, 0, 0],
                  quat=[0.9238795, 0, 0, -0.3826834])
    if options.wrist_camera:
        # Beside the hand, looking along the approach axis towards the point between the fingers.
        cam_pos = np.array([0.05, -0.05, 0.10])
        hand.add_camera(name="wrist", pos=cam_pos.tolist(), fovy=80.0,
                        quat=look_at_quat(cam_pos, np.array([0.0, 0.0, 0.32]),
                                          up=(0.7071, -0.7071, 0.0)).tolist())
    for name in FINGER_ACTUATORS:
        act = spec.actuator(name.removeprefix(PREFIX))
        act.gainprm[0] = 1000.0
        act.biasprm[1] = -1000.0
    return spec


def attach_panda(parent: mujoco.MjSpec, pos: tuple[float, float, float],
                 options: RobotSpecOptions = RobotSpecOptions()) -> None:
    """Attach a fresh Panda to ``parent``'s world body at ``pos`` (base facing +x)."""
    frame = parent.worldbody.add_frame(pos=list(pos))
    parent.attach(panda_spec(options), frame=frame, prefix=PREFIX)


class Robot:
    """Index bookkeeping for the Panda inside a compiled scene (joints and actuators by name)."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.model = model
        self.arm_qpos = np.array([model.joint(n).qposadr[0] for n in ARM_JOINTS])
        self.arm_dof = np.array([model.joint(n).dofadr[0] for n in ARM_JOINTS])
        self.finger_qpos = np.array([model.joint(n).qposadr[0] for n in FINGER_JOINTS])
        self.arm_act = np.array([model.actuator(n).id for n in ARM_ACTUATORS])
        self.finger_act = np.array([model.actuator(n).id for n in FINGER_ACTUATORS])
        self.tcp_site = model.site(TCP_SITE).id
        self.base_body = model.body(BASE_BODY).id
        self.hand_body = model.body(HAND_BODY).id
        self.finger_body_ids = frozenset(model.body(n).id for n in FINGER_BODIES)
        self.body_ids = frozenset(
            b for b in range(model.nbody) if model.body_rootid[b] == model.body_rootid[self.base_body]
        )
        self.arm_limits = model.jnt_range[[model.joint(n).id for n in ARM_JOINTS]].copy()

    def ctrl(self, arm_q: np.ndarray, gripper: float) -> np.ndarray:
        """A full control vector: arm joint targets and gripper opening in [0, 1] (1 = open)."""
        u = np.zeros(self.model.nu)
        u[self.arm_act] = arm_q
        u[self.finger_act] = float(np.clip(gripper, 0.0, 1.0)) * GRIPPER_OPEN
        return u

    def arm_q(self, data: mujoco.MjData) -> np.ndarray:
        return data.qpos[self.arm_qpos].copy()

    def gripper_width(self, data: mujoco.MjData) -> float:
        return float(data.qpos[self.finger_qpos].sum())

    def tcp_pose(self, data: mujoco.MjData) -> tuple[np.ndarray, np.ndarray]:
        return data.site_xpos[self.tcp_site].copy(), data.site_xmat[self.tcp_site].reshape(3, 3).copy()
