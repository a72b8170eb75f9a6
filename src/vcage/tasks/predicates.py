"""Ground-truth predicates: pure functions of the simulator state of a :class:`World`.

They read positions, orientations, contacts and joint values; they never change the world. The
image critic must not use them; the oracle and the task ``evaluate`` methods do. ``ORACLE_CHECKS``
maps every predicate of :mod:`vcage.vocabulary` to its check with the default parameters.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from vcage.assets.catalog import CATALOG
from vcage.geometry import tilt_of
from vcage.registry import Registry
from vcage.scene.spec import ROBOT_MOUNT
from vcage.sim.world import World
from vcage.skills.drawers import opening
from vcage.skills.placements import placement_frame

XY_TOL = 0.01  # slack beyond a placement region's edge
Z_TOL = 0.02  # how far above a surface an object may rest and still be "on" it
SURFACE_TILT = np.pi / 4  # radians a placement surface may tilt and still hold what rests on it
SHUT_TOL = 0.01  # metres a drawer may stand out and still count as shut
HANG_GAP = 0.03  # metres a hanging object's lowest point stays above the table (a mug rack's base: 1.2 cm)
CONTACT_TOL = 0.005  # metres within which an object's lowest point rests on a container's floor or rim


def _in_region(point: np.ndarray, center: np.ndarray, rot: np.ndarray, half: np.ndarray,
               tol: float = XY_TOL) -> bool:
    local = rot.T @ (point - center)
    return bool(np.all(np.abs(local[:2]) <= half + tol))


def contact_between(world: World, a: str, b: str) -> bool:
    """True when any geom of object ``a`` touches any geom of object (or body set) ``b``."""
    ia, ib = world.object_names.index(a), world.object_names.index(b)
    d = world.data
    if d.ncon == 0:
        return False
    g1 = world.object_of_geom(d.contact.geom1[: d.ncon])
    g2 = world.object_of_geom(d.contact.geom2[: d.ncon])
    return bool(np.any(((g1 == ia) & (g2 == ib)) | ((g1 == ib) & (g2 == ia))))


def on(world: World, obj: str, target: str, placement: str | None = None) -> bool:
    """``obj`` rests on ``target``'s placement surface, within its region, and the surface faces up
    (a target tipped over has no placement surface to rest on: the region's frame would lie beside
    it, where an object standing next to a tipped target would count as on it; a cube's surface is
    the face that is up). ``obj`` rests on its base, its origin (the base's centre) on the surface;
    a cube (``any_face``) on whichever face is down: its lowest point and its centre count.

    And ``obj`` touches ``target``: over the region and low enough is not resting on it when
    something else holds ``obj`` up (a cup standing in a basket whose floor lies over a coaster
    beneath it, a few millimetres above the coaster's top, as Vanilla's scenes compose them)."""
    center, rot, half, _ = placement_frame(world, target, placement)
    if CATALOG.get(world.object(obj).type_name).any_face:
        dz, point = world.object_lowest(obj, rot[:, 2], center), world.object_com(obj)
    else:
        dz, point = world.object_pos(obj)[2] - center[2], world.object_pos(obj)
    return (_faces_up(rot) and -0.01 <= dz <= Z_TOL and _in_region(point, center, rot, half)
            and contact_between(world, obj, target))


def inside(world: World, obj: str, container: str, placement: str | None = None) -> bool:
    """``obj`` lies in the container: its centre of mass is over the region, within the walls, and
    its lowest point lies between the floor and the rim, at most :data:`CONTACT_TOL` below the floor
    (pressed into it) and at least that below the rim (within it, ``obj`` rests on the rim, as a
    soap left lying on a drawer's front wall does); the container's opening faces up. Heights and
    the region are taken in the container's frame, so they tip with it. A container whose walls are
    lower than :data:`Z_TOL` (a tray) holds what rests up to that high.

    Not ``obj``'s origin (the centre of its base), which says little once ``obj`` tilts: a loaf
    standing on end in a basket has it above the rim, and one wedged under a tipped basket's raised
    edge, outside the wall, has it within a centimetre of the region.
    """
    center, rot, half, wall = placement_frame(world, container, placement)
    com = rot.T @ (world.object_com(obj) - center)
    low = world.object_lowest(obj, rot[:, 2], center)
    return (_faces_up(rot) and bool(np.all(np.abs(com[:2]) <= half))
            and -CONTACT_TOL <= low <= max(wall - CONTACT_TOL, Z_TOL))


def _faces_up(rot: np.ndarray) -> bool:
    return tilt_of(rot) <= SURFACE_TILT


def on_table(world: World, obj: str, tol: float = 0.01) -> bool:
    """``obj`` rests on the table: one of its geoms touches the table top (within ``tol``).

    Contact, not the height of the object's origin: a cube lying on a side face is on the table
    although its origin (the centre of its bottom face) is half a side higher, and an object on a
    mat or on another object is not, however thin the thing under it.
    """
    d = world.data
    if d.ncon == 0:
        return False
    top = world.model.geom("table/top").id
    g1, g2 = d.contact.geom1[: d.ncon], d.contact.geom2[: d.ncon]
    other = np.where(g1 == top, g2, np.where(g2 == top, g1, -1))
    near = (other >= 0) & (d.contact.dist[: d.ncon] <= tol)
    idx = world.object_names.index(obj)
    return bool(np.any(world.object_of_geom(other[near]) == idx))


def stacked(world: World, objs: list[str]) -> bool:
    """``objs[0]`` is the bottom; each next one rests on the previous one."""
    return all(on(world, upper, lower) for lower, upper in zip(objs, objs[1:], strict=False))


def near(world: World, a: str, b: str, distance: float = 0.1) -> bool:
    return bool(np.linalg.norm(world.object_pos(a)[:2] - world.object_pos(b)[:2]) <= distance)


def left_of(world: World, a: str, b: str, margin: float = 0.03) -> bool:
    """``a`` is left of ``b`` as seen from the robot (+y is left), by at least ``margin``."""
    return bool(world.object_pos(a)[1] >= world.object_pos(b)[1] + margin)


def right_of(world: World, a: str, b: str, margin: float = 0.03) -> bool:
    return bool(world.object_pos(a)[1] <= world.object_pos(b)[1] - margin)


def upright(world: World, obj: str, tol: float = 0.2) -> bool:
    return tilt_of(world.object_mat(obj)) <= tol


def lifted(world: World, obj: str, height: float = 0.05) -> bool:
    return bool(world.object_pos(obj)[2] - world.table_top() >= height)


def grasped(world: World, obj: str) -> bool:
    """Both fingers touch ``obj``."""
    d, robot = world.data, world.robot
    idx = world.object_names.index(obj)
    touching = set()
    for i in range(d.ncon):
        g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
        for ga, gb in ((g1, g2), (g2, g1)):
            body = int(world.model.geom_bodyid[ga])
            if body in robot.finger_body_ids and world.object_of_geom(np.array([gb]))[0] == idx:
                touching.add(body)
    return len(touching) == 2


def joint_displacement(world: World, obj: str, joint: str) -> float:
    """How far ``obj``'s joint has moved from its rest value (absolute, metres or radians)."""
    jid = world.model.joint(f"{obj}/{joint}").id
    rest = float(world.model.qpos_spring[world.model.jnt_qposadr[jid]])
    return abs(float(world.data.qpos[world.model.jnt_qposadr[jid]]) - rest)


def pressed(world: World, obj: str, point: str | None = None) -> bool:
    """The robot presses ``obj``: the functional point's joint is displaced by at least its annotated
    travel while the robot touches ``obj``. Not a button pushed down by something else (a loaf that
    lay on a bell, pressed by the hand; the table under a bell that fell on its top)."""
    inst = world.object(obj)
    fp = CATALOG.get(inst.type_name).functional_point(point)
    if fp.joint is None:
        return False
    travel = fp.travel * (inst.scale if fp.kind in ("button",) else 1.0)
    return joint_displacement(world, obj, fp.joint) >= travel and robot_touches(world, obj)


def robot_touches(world: World, obj: str) -> bool:
    """Some geom of the robot touches ``obj``."""
    d = world.data
    if d.ncon == 0:
        return False
    g1, g2 = d.contact.geom1[: d.ncon], d.contact.geom2[: d.ncon]
    idx = world.object_names.index(obj)
    return bool(np.any((world.geom_is_robot(g1) & (world.object_of_geom(g2) == idx))
                       | (world.geom_is_robot(g2) & (world.object_of_geom(g1) == idx))))


def _drawer_out(world: World, obj: str, point: str | None) -> tuple[float, float] | None:
    """How far ``obj``'s drawer is out (signed: a drawer pushed past its stop is further in than
    shut, not out) and how far counts as open; None if it has no drawer."""
    fp = CATALOG.get(world.object(obj).type_name).drawer_handle(point)
    if fp is None:
        return None
    return opening(world, obj, fp.name), fp.travel


def opened(world: World, obj: str, point: str | None = None) -> bool:
    """``obj``'s drawer is out by at least its handle's annotated travel."""
    out = _drawer_out(world, obj, point)
    return out is not None and out[0] >= out[1]


def closed(world: World, obj: str, point: str | None = None, tol: float = SHUT_TOL) -> bool:
    """``obj``'s drawer is within ``tol`` of shut."""
    out = _drawer_out(world, obj, point)
    return out is not None and out[0] <= tol


def moved(world: World, obj: str, start_xy: np.ndarray, distance: float) -> bool:
    return bool(np.linalg.norm(world.object_pos(obj)[:2] - np.asarray(start_xy)[:2]) >= distance)


def hanging(world: World, obj: str, host: str) -> bool:
    """``obj`` hangs from ``host``: it touches ``host`` and its lowest point stays :data:`HANG_GAP`
    above the table, so it rests neither on the table nor on ``host``'s base: ``host`` holds it up by
    what stands above (a rack's peg). Not :func:`lifted` (its origin's height): a mug lying on its
    side against a rack's base has its origin 6 cm up."""
    low = world.object_lowest(obj, np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, world.table_top()]))
    return low >= HANG_GAP and contact_between(world, obj, host)


def facing(world: World, obj: str, point: str | None = None, tol: float = 0.45) -> bool:
    """``obj``'s functional point (``point``; None: its face, see ``ObjectType.face``) faces the
    robot: its outward ``direction``, turned with the object, points at the robot's base within
    ``tol`` radians (in the horizontal plane). An object without a face faces nowhere."""
    otype = CATALOG.get(world.object(obj).type_name)
    fp = otype.face if point is None else otype.functional_point(point)
    if fp is None:
        return False
    out = (world.object_mat(obj) @ np.asarray(fp.direction, float))[:2]
    to_robot = np.asarray(ROBOT_MOUNT[:2]) - world.object_pos(obj)[:2]
    if np.linalg.norm(out) < 1e-6:
        return False
    cos = float(out @ to_robot) / (float(np.linalg.norm(out)) * float(np.linalg.norm(to_robot)))
    return bool(cos >= np.cos(tol))


# -- the oracle's check of each predicate of the vocabulary, with the default parameters ----------

ORACLE_CHECKS: Registry[Callable[..., bool]] = Registry("oracle check")
ORACLE_CHECKS.add("on", lambda w, a, b: on(w, a, b))
ORACLE_CHECKS.add("inside", lambda w, a, b: inside(w, a, b))
ORACLE_CHECKS.add("stacked", lambda w, *objs: stacked(w, list(objs)))
ORACLE_CHECKS.add("near", lambda w, a, b: near(w, a, b))
ORACLE_CHECKS.add("left_of", lambda w, a, b: left_of(w, a, b))
ORACLE_CHECKS.add("right_of", lambda w, a, b: right_of(w, a, b))
ORACLE_CHECKS.add("on_table", lambda w, a: on_table(w, a, tol=0.02))
ORACLE_CHECKS.add("upright", lambda w, a: upright(w, a))
ORACLE_CHECKS.add("lifted", lambda w, a: lifted(w, a))
ORACLE_CHECKS.add("released", lambda w, a: not grasped(w, a))
ORACLE_CHECKS.add("pressed", lambda w, a: pressed(w, a))  # an event: the oracle latches it
ORACLE_CHECKS.add("opened", lambda w, a: opened(w, a))
ORACLE_CHECKS.add("closed", lambda w, a: closed(w, a))
ORACLE_CHECKS.add("facing", lambda w, a: facing(w, a))
ORACLE_CHECKS.add("hanging", lambda w, a, b: hanging(w, a, b))
