"""A render model of meshes cut to their size: each body's drawn geoms of one look are one mesh.

On a software rasteriser a frame costs its triangles. MuJoCo draws every box face as 4 x 4 squares
and every cylinder in 8 bands with 4-ring caps (its visual quality), whatever their size, so that
lighting, computed at the corners, keeps the highlight of a large face; a scene of small objects
pays for all of them. :func:`batched_model` recompiles the scene's ``MjSpec`` with, in every body,
the drawn geoms (groups 0-2, opaque, untextured: the objects' collision shapes, which are what is
drawn of them, and the robot's visual meshes) that share a material and colour replaced by one mesh
of their triangles in the body's frame: the robot's simplified meshes from the level-of-detail model
(:mod:`vcage.sim.lod`), primitives tessellated as MuJoCo draws them but cut into squares no smaller
than :data:`SQUARE` (a block's face is one square, the table top 4 x 4). Spheres and the round
outlines keep the level-of-detail model's slices and stacks, so silhouettes are unchanged. Merging
the geoms of a body saves no measurable time by itself (``benchmarks/render_lod.py``); cutting faces
to their size does.

The replaced geoms stay, moved to a group that is not drawn (deleting from a spec costs
milliseconds a geom), and the robot's full visual meshes are emptied (neither compiled nor
uploaded). The spec is built afresh by the world's ``spec`` callable (keeping a compiled spec would
hold tens of MiB). Bodies, joints, cameras, lights and visual options are the spec's own: the
batched model has the original's bodies in the same order and draws any of its states once its
kinematics are computed on its own data, which :class:`vcage.sim.render.Renderer` does before each
frame. It is never stepped.
"""

from __future__ import annotations

from collections import OrderedDict, defaultdict
from collections.abc import Callable

import mujoco
import numpy as np

from vcage.errors import ConfigError
from vcage.sim.lod import lod_model

_T = mujoco.mjtGeom
BATCHED_TYPES = (int(_T.mjGEOM_BOX), int(_T.mjGEOM_SPHERE), int(_T.mjGEOM_ELLIPSOID),
                 int(_T.mjGEOM_CYLINDER), int(_T.mjGEOM_CAPSULE), int(_T.mjGEOM_MESH))
DRAWN_GROUPS = (0, 1, 2)  # the geom groups a renderer draws by default (3: the robot's collision geoms)
UNDRAWN_GROUP = 5  # where the parts of a merged geom go
# The largest square (metres) a flat face is cut into: MuJoCo cuts every face of a box into the
# visual quality's 4 x 4 squares and every cylinder into bands and rings, so that lighting, computed at
# the corners, keeps a large face's highlight; a block's 4.5 cm face looks the same as one square
# (benchmarks/render_lod.py: the same pixels, three quarters of the time)
SQUARE = 0.05
BATCHED = "__batched"  # name prefix of the merged meshes and geoms

_CACHE: OrderedDict[int, tuple[mujoco.MjModel, tuple[mujoco.MjModel, np.ndarray]]] = OrderedDict()
_CACHE_SIZE = 2  # a run's renderers (critic views, videos) draw one scene after another


def batched(model: mujoco.MjModel, spec: Callable[[], mujoco.MjSpec]) -> tuple[mujoco.MjModel, np.ndarray]:
    """:func:`batched_model` of ``model``'s level-of-detail copy and its spec (built by ``spec``),
    compiled once per model (the last few are kept)."""
    hit = _CACHE.get(id(model))
    if hit is not None and hit[0] is model:
        _CACHE.move_to_end(id(model))
        return hit[1]
    out = batched_model(lod_model(model), spec())
    _CACHE[id(model)] = (model, out)
    while len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return out


def batched_model(lod: mujoco.MjModel, spec: mujoco.MjSpec) -> tuple[mujoco.MjModel, np.ndarray]:
    """The batched model of ``spec`` (whose compiled model ``lod`` is the level-of-detail copy of;
    ``spec`` is changed), and for each of its geoms a geom of the original's it stands for."""
    geoms = _compiled_order(spec, lod)
    groups: dict[tuple, list[int]] = defaultdict(list)
    for g in range(lod.ngeom):
        if _batchable(lod, g):
            key = (int(lod.geom_bodyid[g]), int(lod.geom_matid[g]), int(lod.geom_group[g]),
                   tuple(np.round(lod.geom_rgba[g], 6)))
            groups[key].append(g)
    bodies = {b.name: b for b in spec.bodies}
    replaced: set[int] = set()
    # a geom alone is rewritten too: the robot's links, whose simplified meshes compile in no time
    for n, ((body, matid, group, rgba), parts) in enumerate(groups.items()):
        vertices, normals = _triangles(lod, parts)
        mesh = spec.add_mesh(name=f"{BATCHED}{n}")
        mesh.uservert = vertices.ravel().tolist()
        mesh.usernormal = normals.ravel().tolist()
        faces = np.arange(len(vertices), dtype=np.int32)
        mesh.userface = faces.tolist()
        mesh.userfacenormal = faces.tolist()
        mesh.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_SHELL
        parent = spec.worldbody if body == 0 else bodies[lod.body(body).name]
        geom = parent.add_geom(name=f"{BATCHED}{n}", type=_T.mjGEOM_MESH, meshname=mesh.name,
                               rgba=list(rgba), group=group, contype=0, conaffinity=0, mass=0)
        if matid >= 0:
            geom.material = lod.mat(matid).name
        for g in parts:  # kept, not drawn (deleting a geom from a spec costs milliseconds)
            geoms[g].group = UNDRAWN_GROUP
            replaced.add(g)
    # The robot's full visual meshes, which only replaced geoms draw, are emptied: neither compiled
    # nor uploaded (emptied, not deleted: deleting a mesh from a spec never compiled corrupts the heap)
    needed = {geoms[g].meshname for g in range(lod.ngeom) if g not in replaced}
    for mesh in spec.meshes:
        if mesh.name not in needed and not mesh.name.startswith(BATCHED):
            mesh.file = ""
            mesh.uservert = [0, 0, 0, 1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3]  # a tetrahedron
    spec.stat.extent, spec.stat.center = float(lod.stat.extent), lod.stat.center.copy()
    model = lod_model(spec.compile(), keep=BATCHED)
    if model.nbody != lod.nbody or model.ncam != lod.ncam:
        raise ConfigError("the batched render model lost bodies or cameras; render with mesh_detail='full'")
    return model, _sources(model, lod)


def _compiled_order(spec: mujoco.MjSpec, model: mujoco.MjModel) -> list:
    """The spec's geoms in the compiled model's order (checked against their types)."""
    geoms = list(spec.geoms)
    if len(geoms) != model.ngeom or any(int(s.type) != int(model.geom_type[i]) for i, s in enumerate(geoms)):
        raise ConfigError("the scene's MjSpec does not match its compiled model; "
                          "render with mesh_detail='full'")
    return geoms


def _batchable(model: mujoco.MjModel, g: int) -> bool:
    matid = int(model.geom_matid[g])
    textured = matid >= 0 and bool(np.any(model.mat_texid[matid] >= 0))
    return (int(model.geom_type[g]) in BATCHED_TYPES and int(model.geom_group[g]) in DRAWN_GROUPS
            and model.geom_rgba[g][3] >= 1.0 and not textured)


def _sources(model: mujoco.MjModel, lod: mujoco.MjModel) -> np.ndarray:
    """For each geom of the batched model, a geom of the original's on the same body (what a pixel
    shows is told by its body: which object, or the robot)."""
    first: dict[int, int] = {}
    for g in range(lod.ngeom):
        first.setdefault(int(lod.geom_bodyid[g]), g)
    return np.array([first[int(b)] for b in model.geom_bodyid], dtype=np.int64)


def _triangles(model: mujoco.MjModel, geoms: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """The triangles of ``geoms`` in their body's frame: (3 n, 3) corners and their normals."""
    verts, norms = [], []
    for g in geoms:
        v, n = _shape(model, g)
        flat = np.empty(9)
        mujoco.mju_quat2Mat(flat, model.geom_quat[g])
        rot = flat.reshape(3, 3)
        verts.append(v @ rot.T + model.geom_pos[g])
        norms.append(n @ rot.T)
    return np.concatenate(verts).astype(np.float64), np.concatenate(norms).astype(np.float64)


def _shape(model: mujoco.MjModel, g: int) -> tuple[np.ndarray, np.ndarray]:
    """Triangle corners and normals of geom ``g`` in its own frame, tessellated as the renderer
    draws it (slices and stacks of the model's visual quality)."""
    kind, size = int(model.geom_type[g]), model.geom_size[g]
    q = model.vis.quality
    slices, stacks, quads = int(q.numslices), int(q.numstacks), int(q.numquads)
    if kind == int(_T.mjGEOM_MESH):
        mesh = int(model.geom_dataid[g])
        va, na, fa, fn = (model.mesh_vertadr[mesh], model.mesh_normaladr[mesh], model.mesh_faceadr[mesh],
                          model.mesh_facenum[mesh])
        faces = model.mesh_face[fa:fa + fn]
        fnorm = model.mesh_facenormal[fa:fa + fn]
        return model.mesh_vert[va + faces].reshape(-1, 3), model.mesh_normal[na + fnorm].reshape(-1, 3)
    if kind == int(_T.mjGEOM_BOX):
        return _box(size, quads)
    if kind in (int(_T.mjGEOM_SPHERE), int(_T.mjGEOM_ELLIPSOID)):
        radii = np.full(3, size[0]) if kind == int(_T.mjGEOM_SPHERE) else size[:3]
        return _ellipsoid(radii, slices, stacks)
    if kind == int(_T.mjGEOM_CYLINDER):
        return _cylinder(size[0], size[1], slices, _squares(2 * size[1], stacks), _squares(size[0], quads))
    return _capsule(size[0], size[1], slices, stacks)


def _quads(corners: np.ndarray, normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two triangles per quad: ``corners`` and ``normals`` (q, 4, 3), counter-clockwise from outside."""
    idx = [0, 1, 3, 1, 2, 3]
    return corners[:, idx].reshape(-1, 3), normals[:, idx].reshape(-1, 3)


def _box(half: np.ndarray, quads: int) -> tuple[np.ndarray, np.ndarray]:
    """Each face a grid of at most ``quads`` x ``quads`` squares, as the renderer draws it, but no
    finer than :data:`SQUARE` (lighting is computed at the corners: a large face drawn as one square
    would lose its highlight, a small one looks the same)."""
    corners, normals = [], []
    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        n_sq = _squares(2 * max(half[u], half[w]), quads)
        steps = np.linspace(-1.0, 1.0, n_sq + 1)
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            for i in range(n_sq):
                for j in range(n_sq):
                    face = []
                    for a, b in ((steps[i], steps[j]), (steps[i + 1], steps[j]), (steps[i + 1], steps[j + 1]),
                                 (steps[i], steps[j + 1])):
                        p = np.zeros(3)
                        p[axis], p[u], p[w] = sign, a, b * sign  # counter-clockwise seen from outside
                        face.append(p * half)
                    corners.append(face)
                    normals.append([n] * 4)
    return _quads(np.array(corners), np.array(normals))


def _squares(extent: float, most: int) -> int:
    return int(min(most, max(1, np.ceil(extent / SQUARE))))


def _ring(slices: int) -> np.ndarray:
    t = np.linspace(0.0, 2 * np.pi, slices + 1)
    return np.stack([np.cos(t), np.sin(t)], axis=1)


def _ellipsoid(radii: np.ndarray, slices: int, stacks: int) -> tuple[np.ndarray, np.ndarray]:
    ring = _ring(slices)
    phi = np.linspace(-np.pi / 2, np.pi / 2, stacks + 1)
    unit = np.array([[[np.cos(p) * c, np.cos(p) * s, np.sin(p)] for c, s in ring] for p in phi])
    quads = np.stack([unit[:-1, :-1], unit[:-1, 1:], unit[1:, 1:], unit[1:, :-1]], axis=2).reshape(-1, 4, 3)
    normals = quads / radii
    normals /= np.linalg.norm(normals, axis=2, keepdims=True)
    return _quads(quads * radii, normals)


def _cylinder(radius: float, half: float, slices: int, stacks: int,
              rings: int) -> tuple[np.ndarray, np.ndarray]:
    """The side in ``stacks`` bands of ``slices`` squares, each cap in ``rings`` rings (the
    renderer's own tessellation: lighting is computed at the corners)."""
    ring = _ring(slices)
    side_n = np.concatenate([ring, np.zeros((len(ring), 1))], axis=1)
    heights = np.linspace(-half, half, stacks + 1)
    quads, normals = [], []
    for z0, z1 in zip(heights[:-1], heights[1:], strict=True):
        low, high = side_n * radius + [0, 0, z0], side_n * radius + [0, 0, z1]
        quads.append(np.stack([low[:-1], low[1:], high[1:], high[:-1]], axis=1))
        normals.append(np.stack([side_n[:-1], side_n[1:], side_n[1:], side_n[:-1]], axis=1))
    verts, norms = _quads(np.concatenate(quads), np.concatenate(normals))
    out_v, out_n = [verts], [norms]
    radii = np.linspace(0.0, radius, rings + 1)
    for sign in (-1.0, 1.0):
        cap = []
        for r0, r1 in zip(radii[:-1], radii[1:], strict=True):
            inner, outer = side_n * r0 + [0, 0, sign * half], side_n * r1 + [0, 0, sign * half]
            if sign > 0:
                cap.append(np.stack([inner[:-1], outer[:-1], outer[1:], inner[1:]], axis=1))
            else:
                cap.append(np.stack([inner[1:], outer[1:], outer[:-1], inner[:-1]], axis=1))
        q = np.concatenate(cap)
        v, _ = _quads(q, q)
        out_v.append(v)
        out_n.append(np.broadcast_to([0.0, 0.0, sign], v.shape))
    return np.concatenate(out_v), np.concatenate(out_n)


def _capsule(radius: float, half: float, slices: int, stacks: int) -> tuple[np.ndarray, np.ndarray]:
    bands = _squares(2 * half, stacks)
    side_v, side_n = _cylinder(radius, half, slices, bands, 1)
    side_v, side_n = side_v[:slices * 6 * bands], side_n[:slices * 6 * bands]  # without the caps
    ball_v, ball_n = _ellipsoid(np.full(3, radius), slices, stacks)
    upper = np.repeat(ball_v.reshape(-1, 3, 3)[:, :, 2].mean(axis=1) >= 0, 3)  # by triangle: no seam
    ball_v = ball_v + np.where(upper, half, -half)[:, None] * np.array([0.0, 0.0, 1.0])
    return np.concatenate([side_v, ball_v]), np.concatenate([side_n, ball_n])
