"""Toys: a foam die, a toy car, a tennis ball and a Rubik's cube."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from vcage.assets.annotations import S2, Annotations, StableOrientation, grasp_pair
from vcage.assets.catalog import CATALOG, ObjectType
from vcage.assets.parts import DARK, VISUAL, WHITE, Y_AXIS_QUAT, PartBuilder


def _cube_faces(half: float) -> Iterator[tuple[str, np.ndarray, np.ndarray, np.ndarray]]:
    """The faces of a cube of half edge ``half`` resting on z=0: name, centre, two in-face axes."""
    c = np.array([0.0, 0.0, half])
    ex, ey, ez = np.eye(3)
    yield "top", c + half * ez, ex, ey
    yield "bottom", c - half * ez, ex, ey
    yield "east", c + half * ex, ey, ez
    yield "west", c - half * ex, ey, ez
    yield "north", c + half * ey, ex, ez
    yield "south", c - half * ey, ex, ez


# --- dice ---------------------------------------------------------------------------------------
DICE = 0.04
_PIP = 0.0105
_PIPS = {
    1: [(0, 0)],
    2: [(-1, -1), (1, 1)],
    3: [(-1, -1), (0, 0), (1, 1)],
    4: [(-1, -1), (-1, 1), (1, -1), (1, 1)],
    5: [(-1, -1), (-1, 1), (0, 0), (1, -1), (1, 1)],
    6: [(-1, -1), (-1, 0), (-1, 1), (1, -1), (1, 0), (1, 1)],
}
_DICE_FACES = {"top": 1, "bottom": 6, "east": 2, "west": 5, "north": 3, "south": 4}


def _dice(p: PartBuilder) -> None:
    h = DICE / 2
    p.box([h, h, h], [0, 0, h], name="body")
    pip_rgba = WHITE if sum(p.rgba[:3]) < 1.8 else DARK
    for face, centre, u, v in _cube_faces(h):
        n = _DICE_FACES[face]
        inward = np.array([0.0, 0.0, h]) - centre
        inward /= np.linalg.norm(inward)
        for k, (a, b) in enumerate(_PIPS[n]):
            pos = centre + _PIP * (a * u + b * v) + 0.0028 * inward
            p.sphere(0.0035, pos.tolist(), pip_rgba, name=f"pip{n}_{k}", **VISUAL)


CATALOG.add_type(ObjectType(
    name="dice", category="toy", description="a large foam die",
    size=(DICE, DICE, DICE), mass=0.03,
    colors={"white": (0.95, 0.95, 0.93, 1.0), "red": (0.8, 0.12, 0.12, 1.0),
            "green": (0.2, 0.6, 0.3, 1.0)},
    build=_dice, tags=frozenset({"graspable", "toy", "stackable", "cube"}), scale_range=(0.95, 1.1),
    any_face=True,
    annotations=Annotations(
        grasps=grasp_pair("top", (0, 0, 0.025), DICE),
        stable_orientations=(
            StableOrientation("1_up"),
            StableOrientation("6_up", (0.0, 1.0, 0.0, 0.0)),
            StableOrientation("2_up", (S2, 0.0, -S2, 0.0)),
            StableOrientation("5_up", (S2, 0.0, S2, 0.0)),
            StableOrientation("3_up", (S2, S2, 0.0, 0.0)),
            StableOrientation("4_up", (S2, -S2, 0.0, 0.0)),
        ),
    ),
))

# --- toy car ------------------------------------------------------------------------------------
CAR = (0.1, 0.054, 0.05)
CAR_WHEEL_R = 0.012


def _toy_car(p: PartBuilder) -> None:
    r = CAR_WHEEL_R
    p.box([0.05, 0.022, 0.01], [0, 0, r + 0.01], name="chassis")
    p.box([0.026, 0.019, 0.009], [-0.006, 0, r + 0.029], name="cabin")
    p.box([0.0005, 0.015, 0.006], [0.0205, 0, r + 0.029], (0.6, 0.8, 0.95, 1.0), name="windshield",
          **VISUAL)
    for i, (sx, sy) in enumerate(((1, 1), (1, -1), (-1, 1), (-1, -1))):
        p.cylinder(r, 0.005, [sx * 0.032, sy * (CAR[1] / 2 - 0.005), r], DARK, name=f"wheel{i}",
                   quat=Y_AXIS_QUAT)


CATALOG.add_type(ObjectType(
    name="toy_car", category="toy", description="a small toy car",
    size=CAR, mass=0.08,
    colors={"red": (0.85, 0.12, 0.1, 1.0), "blue": (0.15, 0.35, 0.85, 1.0),
            "yellow": (0.95, 0.8, 0.1, 1.0), "green": (0.2, 0.65, 0.3, 1.0)},
    build=_toy_car, tags=frozenset({"graspable", "toy"}),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.032), CAR[1], second=math.pi)),
))

# --- tennis ball --------------------------------------------------------------------------------
BALL_R = 0.0325


def _tennis_ball(p: PartBuilder) -> None:
    ball = p.sphere(BALL_R, [0, 0, BALL_R], name="ball")
    ball.condim = 6  # rolling friction: the ball slows down instead of rolling forever
    ball.friction = [p.friction, 0.005, 0.002]


CATALOG.add_type(ObjectType(
    name="tennis_ball", category="toy", description="a tennis ball",
    size=(2 * BALL_R, 2 * BALL_R, 2 * BALL_R), mass=0.058,
    colors={"yellow": (0.85, 0.92, 0.2, 1.0), "orange": (0.98, 0.6, 0.15, 1.0)},
    build=_tennis_ball, tags=frozenset({"graspable", "toy", "round", "rollable"}),
    scale_range=(0.95, 1.05),
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, BALL_R), 2 * BALL_R)),
))

# --- Rubik's cube -------------------------------------------------------------------------------
RUBIK = 0.057
_RUBIK_COLORS = {
    "top": WHITE, "bottom": (0.98, 0.85, 0.1, 1.0), "east": (0.8, 0.1, 0.1, 1.0),
    "west": (0.98, 0.5, 0.1, 1.0), "north": (0.1, 0.3, 0.8, 1.0), "south": (0.1, 0.62, 0.25, 1.0),
}


def _rubik_cube(p: PartBuilder) -> None:
    h = RUBIK / 2
    p.box([h, h, h], [0, 0, h], name="body")
    cell = RUBIK / 3
    for face, centre, u, v in _cube_faces(h):
        normal = centre - np.array([0.0, 0.0, h])
        normal /= np.linalg.norm(normal)
        half = np.abs(u) * cell * 0.42 + np.abs(v) * cell * 0.42 + np.abs(normal) * 0.0004
        for i in (-1, 0, 1):
            for j in (-1, 0, 1):
                pos = centre + cell * (i * u + j * v) + 0.0003 * normal
                p.box(half.tolist(), pos.tolist(), _RUBIK_COLORS[face], name=f"{face}{i + 1}{j + 1}",
                      **VISUAL)


CATALOG.add_type(ObjectType(
    name="rubik_cube", category="toy", description="a Rubik's cube",
    size=(RUBIK, RUBIK, RUBIK), mass=0.09,
    colors={"black": (0.08, 0.08, 0.09, 1.0)},
    build=_rubik_cube, tags=frozenset({"graspable", "toy", "stackable", "cube", "colorful"}),
    scale_range=(0.95, 1.05), any_face=True,
    annotations=Annotations(grasps=grasp_pair("top", (0, 0, 0.035), RUBIK)),
))
