"""Geometry helpers that builders use to add parts to an object's body in an ``MjSpec``.

Every geom and joint is named ``<instance>/<part>`` so that segmentation and predicates can map
simulator ids back to catalog objects. Hollow objects (cups, bowls, baskets) are built from a floor
and a ring of box walls, so they really contain what is put in them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from vcage.geometry import mat_to_quat, rot_y, rot_z

if TYPE_CHECKING:
    import mujoco

RGBA = tuple[float, ...]  # (r, g, b, a)
VISUAL: dict[str, Any] = {"contype": 0, "conaffinity": 0}  # geom options for decoration only
DARK: RGBA = (0.12, 0.12, 0.13, 1.0)  # black plastic parts
METAL: RGBA = (0.78, 0.78, 0.8, 1.0)  # steel parts
WHITE: RGBA = (0.95, 0.95, 0.94, 1.0)  # white plastic and paper parts
X_AXIS_QUAT = (math.sqrt(0.5), 0.0, math.sqrt(0.5), 0.0)  # turns a cylinder's or capsule's axis onto x
Y_AXIS_QUAT = (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0)  # turns a cylinder's or capsule's axis onto y


class PartBuilder:
    """Adds named parts to one body; ``scale`` multiplies every length given to it."""

    def __init__(self, body: mujoco.MjsBody, prefix: str, scale: float, rgba: RGBA,
                 friction: float = 1.0) -> None:
        import mujoco  # here, not at the top: the catalog's metadata is read without the simulator

        self._mj = mujoco
        self.body = body
        self.prefix = prefix
        self.scale = scale
        self.rgba = rgba
        self.friction = friction
        self._count = 0

    def _name(self, name: str | None) -> str:
        self._count += 1
        return f"{self.prefix}/{name or f'g{self._count}'}"

    def _geom(self, gtype: mujoco.mjtGeom, size: Sequence[float], pos: Sequence[float],
              rgba: RGBA | None, name: str | None, quat: Sequence[float] | None,
              body: mujoco.MjsBody | None, **kw: Any) -> mujoco.MjsGeom:
        s = self.scale
        target = body if body is not None else self.body
        geom = target.add_geom(
            name=self._name(name), type=gtype,
            size=[v * s for v in size] + [0.0] * (3 - len(size)),
            pos=[v * s for v in pos],
            rgba=list(rgba or self.rgba),
            friction=[self.friction, 0.005, 0.0001],
            condim=kw.pop("condim", 4),
        )
        if quat is not None:
            geom.quat = list(quat)
        for key, value in kw.items():
            setattr(geom, key, value)
        return geom

    def box(self, half: Sequence[float], pos: Sequence[float] = (0, 0, 0), rgba: RGBA | None = None,
            name: str | None = None, quat: Sequence[float] | None = None,
            body: mujoco.MjsBody | None = None, **kw: Any) -> mujoco.MjsGeom:
        return self._geom(self._mj.mjtGeom.mjGEOM_BOX, half, pos, rgba, name, quat, body, **kw)

    def cylinder(self, radius: float, half_height: float, pos: Sequence[float] = (0, 0, 0),
                 rgba: RGBA | None = None, name: str | None = None,
                 quat: Sequence[float] | None = None, body: mujoco.MjsBody | None = None,
                 **kw: Any) -> mujoco.MjsGeom:
        return self._geom(self._mj.mjtGeom.mjGEOM_CYLINDER, [radius, half_height], pos, rgba, name,
                          quat, body, **kw)

    def sphere(self, radius: float, pos: Sequence[float] = (0, 0, 0), rgba: RGBA | None = None,
               name: str | None = None, body: mujoco.MjsBody | None = None,
               **kw: Any) -> mujoco.MjsGeom:
        return self._geom(self._mj.mjtGeom.mjGEOM_SPHERE, [radius], pos, rgba, name, None, body, **kw)

    def capsule(self, radius: float, half_length: float, pos: Sequence[float] = (0, 0, 0),
                rgba: RGBA | None = None, name: str | None = None,
                quat: Sequence[float] | None = None, body: mujoco.MjsBody | None = None,
                **kw: Any) -> mujoco.MjsGeom:
        return self._geom(self._mj.mjtGeom.mjGEOM_CAPSULE, [radius, half_length], pos, rgba, name,
                          quat, body, **kw)

    def ring(self, radius: float, height: float, thickness: float, segments: int = 12,
             z0: float = 0.0, rgba: RGBA | None = None, body: mujoco.MjsBody | None = None,
             name: str = "wall") -> None:
        """A ring of upright box walls from ``z0`` to ``z0 + height`` with inner radius ``radius``."""
        seg_len = 2 * radius * math.tan(math.pi / segments) + thickness
        r = radius + thickness / 2
        for i in range(segments):
            ang = 2 * math.pi * i / segments
            pos = [r * math.cos(ang), r * math.sin(ang), z0 + height / 2]
            self.box([thickness / 2, seg_len / 2, height / 2], pos, rgba, name=f"{name}{i}",
                     quat=mat_to_quat(rot_z(ang)).tolist(), body=body)

    def flared_ring(self, r0: float, r1: float, z0: float, z1: float, thickness: float,
                    segments: int, name: str = "wall") -> list[mujoco.MjsGeom]:
        """A ring of box walls whose inner surface runs from radius ``r0`` at ``z0`` to ``r1`` at ``z1``.

        With ``r1 > r0`` the walls open outwards, so a second copy of the object nests inside.
        """
        tilt = math.atan2(r1 - r0, z1 - z0)
        length = math.hypot(r1 - r0, z1 - z0)
        half_w = (r1 + thickness) * math.tan(math.pi / segments)
        normal = (math.cos(tilt), -math.sin(tilt))  # outward normal in the (r, z) plane
        rc = (r0 + r1) / 2 + normal[0] * thickness / 2
        zc = (z0 + z1) / 2 + normal[1] * thickness / 2
        geoms = []
        for i in range(segments):
            ang = 2 * math.pi * i / segments
            quat = mat_to_quat(rot_z(ang) @ rot_y(tilt)).tolist()
            geoms.append(self.box([thickness / 2, half_w, length / 2],
                                  [rc * math.cos(ang), rc * math.sin(ang), zc], name=f"{name}{i}",
                                  quat=quat))
        return geoms

    def open_cylinder(self, radius: float, height: float, thickness: float, floor: float,
                      segments: int = 16) -> None:
        """A round container (a cup, a pot): a floor disc of radius ``radius`` and ``floor`` thick,
        and a ring of walls, ``thickness`` thick, up to ``height`` with outer radius ``radius``."""
        self.cylinder(radius, floor / 2, [0, 0, floor / 2], name="floor")
        self.ring(radius - thickness, height - floor, thickness, segments=segments, z0=floor)

    def open_box(self, half_x: float, half_y: float, wall: float, thickness: float, floor: float) -> None:
        """A rectangular container (a basket, a tray): a floor plate ``floor`` thick and four walls
        ``wall`` high on it around the inner rectangle of half extents ``half_x``, ``half_y``."""
        t = thickness
        self.box([half_x + t, half_y + t, floor / 2], [0, 0, floor / 2], name="floor")
        self.rect_walls(half_x, half_y, wall, t, z0=floor)

    def rect_walls(self, half_x: float, half_y: float, height: float, thickness: float,
                   z0: float = 0.0, rgba: RGBA | None = None, body: mujoco.MjsBody | None = None,
                   name: str = "wall") -> None:
        """Four box walls around a rectangle of half extents ``half_x``, ``half_y``."""
        t = thickness / 2
        zc = z0 + height / 2
        self.box([half_x + thickness, t, height / 2], [0, half_y + t, zc], rgba, f"{name}_n", body=body)
        self.box([half_x + thickness, t, height / 2], [0, -half_y - t, zc], rgba, f"{name}_s", body=body)
        self.box([t, half_y, height / 2], [half_x + t, 0, zc], rgba, f"{name}_e", body=body)
        self.box([t, half_y, height / 2], [-half_x - t, 0, zc], rgba, f"{name}_w", body=body)

    def mesh(self, name: str, vertices: np.ndarray, faces: np.ndarray, spec: mujoco.MjSpec,
             pos: Sequence[float] = (0, 0, 0), rgba: RGBA | None = None,
             body: mujoco.MjsBody | None = None, **kw: Any) -> mujoco.MjsGeom:
        """A convex mesh geom from vertices and faces (e.g. generated with trimesh)."""
        mesh_name = f"{self.prefix}/{name}_mesh"
        spec.add_mesh(name=mesh_name, uservert=(np.asarray(vertices) * self.scale).flatten().tolist(),
                      userface=np.asarray(faces, dtype=int).flatten().tolist())
        target = body if body is not None else self.body
        geom = target.add_geom(name=self._name(name), type=self._mj.mjtGeom.mjGEOM_MESH,
                               meshname=mesh_name, pos=[v * self.scale for v in pos],
                               rgba=list(rgba or self.rgba),
                               friction=[self.friction, 0.005, 0.0001], condim=4)
        for key, value in kw.items():
            setattr(geom, key, value)
        return geom

    def child(self, name: str, pos: Sequence[float] = (0, 0, 0), mass: float = 0.01) -> mujoco.MjsBody:
        """A child body (for articulated parts); add a joint to it with :meth:`slide` or :meth:`hinge`."""
        body = self.body.add_body(name=f"{self.prefix}/{name}", pos=[v * self.scale for v in pos])
        body.mass = mass
        body.inertia = [1e-5, 1e-5, 1e-5]
        body.explicitinertial = True
        return body

    def slide(self, body: mujoco.MjsBody, name: str, axis: Sequence[float], range_: tuple[float, float],
              stiffness: float, damping: float = 0.5, springref: float = 0.0) -> mujoco.MjsJoint:
        return body.add_joint(
            name=f"{self.prefix}/{name}", type=self._mj.mjtJoint.mjJNT_SLIDE, axis=list(axis),
            range=[range_[0] * self.scale, range_[1] * self.scale], limited=True,
            stiffness=stiffness, damping=damping, springref=springref * self.scale,
        )

    def hinge(self, body: mujoco.MjsBody, name: str, axis: Sequence[float], range_: tuple[float, float],
              stiffness: float = 0.0, damping: float = 0.05, springref: float = 0.0, ref: float = 0.0,
              pos: Sequence[float] = (0, 0, 0)) -> mujoco.MjsJoint:
        """A limited hinge; ``range_``, ``springref`` and ``ref`` are in radians.

        MjSpec compiles joint angles in the spec's angle unit (degrees unless the compiler says
        otherwise), so they are converted here, once, for every builder.
        """
        def angle(radians: float) -> float:
            return math.degrees(radians) if body.compiler.degree else radians

        return body.add_joint(
            name=f"{self.prefix}/{name}", type=self._mj.mjtJoint.mjJNT_HINGE, axis=list(axis),
            range=[angle(range_[0]), angle(range_[1])], limited=True, stiffness=stiffness,
            damping=damping, springref=angle(springref), ref=angle(ref),
            pos=[v * self.scale for v in pos],
        )

