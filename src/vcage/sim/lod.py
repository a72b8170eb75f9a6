"""Level-of-detail visual meshes: what the renderer draws in place of heavy visual-only meshes.

On a software rasteriser a frame costs its geometry, and the Panda's visual meshes are about
134,000 of a plan scene's 136,000 faces. :func:`lod_model` returns a copy of a compiled model in
which every mesh drawn only by visual geoms (``contype = conaffinity = 0``) with more than
``budget`` faces is replaced by a quadric decimation of itself (``fast_simplification``), written
into the mesh's own slots: a mesh only shrinks, so the copy has the original's sizes and draws the
original's ``MjData``. It also tessellates primitives more coarsely (:data:`LOD_QUALITY`), which
with the robot simplified is most of what is left to draw. The copy is for drawing only; the model
that is stepped is never changed, so collision geoms, masses and kinematics stay those of the full
model.

Each simplified mesh is computed once per machine and cached in :func:`cache_dir` (beside the
reach map) under a hash of the mesh's vertices and faces, as MuJoCo compiled them from the source
file, and of the budget; a corrupt cache file is computed again and overwritten.
"""

from __future__ import annotations

import contextlib
import copy
import hashlib
import os
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from vcage.config import MESH_DETAILS, cache_dir
from vcage.errors import ConfigError

FACE_BUDGET = 1000  # faces per simplified mesh; see benchmarks/render_lod.py for what it costs
# How finely the renderer tessellates primitives (cylinders, spheres, capsules: slices around and
# stacks along; boxes and planes: quads per side, over which lighting is interpolated). MuJoCo's
# defaults are (28, 16, 4); with the robot's meshes simplified, the objects' round primitives are
# much of a frame's geometry. Fewer quads would save more but change the shading of large faces
# close to the wrist camera (benchmarks/render_lod.py: what it costs and what it changes).
LOD_QUALITY = (16, 8, 4)
# A plane is drawn as a grid of squares its third size sets (the floor: 0.1 m, so 60 x 60 squares and
# as many triangles as the simplified robot); at this spacing its shading moves by under 0.1 level of
# 255 on average (benchmarks/render_lod.py)
PLANE_GRID = 0.3
VERSION = 1  # bump when the simplification or the cache format changes


@dataclass(frozen=True)
class SimpleMesh:
    vertices: np.ndarray  # (n, 3) float32, in the compiled mesh's frame
    faces: np.ndarray  # (m, 3) int32 indices into vertices
    normals: np.ndarray  # (n, 3) float32 unit vertex normals



def render_model(model: mujoco.MjModel, mesh_detail: str) -> mujoco.MjModel:
    """The model a renderer draws for ``mesh_detail``: ``model`` itself (``"full"``) or its
    :func:`lod_model` copy (``"lod"``)."""
    if mesh_detail not in MESH_DETAILS:
        raise ConfigError(f"unknown mesh detail {mesh_detail!r}; choose one of {', '.join(MESH_DETAILS)}")
    return model if mesh_detail == "full" else lod_model(model)


def lod_model(model: mujoco.MjModel, budget: int | None = None,
              quality: tuple[int, int, int] | None = LOD_QUALITY, keep: str | None = None) -> mujoco.MjModel:
    """A copy of ``model`` whose heavy visual-only meshes are simplified to ``budget`` faces
    (None: :data:`FACE_BUDGET` as it is now) and whose primitives are drawn with ``quality``
    (slices, stacks, quads, and planes with grid squares of at least :data:`PLANE_GRID`; None: the
    model's own). Meshes whose names start with ``keep`` are left as they are."""
    budget = FACE_BUDGET if budget is None else budget
    out = copy.copy(model)
    for mesh in heavy_visual_meshes(model, budget):
        if keep is not None and model.mesh(mesh).name.startswith(keep):
            continue
        _write_mesh(out, mesh, simplified(*mesh_arrays(model, mesh), budget))
    if quality is not None:
        q = out.vis.quality
        q.numslices, q.numstacks, q.numquads = quality
        planes = out.geom_type == int(mujoco.mjtGeom.mjGEOM_PLANE)
        out.geom_size[planes, 2] = np.maximum(out.geom_size[planes, 2], PLANE_GRID)
    return out


def heavy_visual_meshes(model: mujoco.MjModel, budget: int) -> list[int]:
    """Meshes with more than ``budget`` faces that only visual geoms draw (no collision geom, no
    texture coordinates to carry over)."""
    mesh_type = int(mujoco.mjtGeom.mjGEOM_MESH)
    uses = model.geom_dataid[model.geom_type == mesh_type]
    collides = (model.geom_contype != 0) | (model.geom_conaffinity != 0)
    colliding = set(model.geom_dataid[(model.geom_type == mesh_type) & collides].tolist())
    return [int(m) for m in sorted(set(uses.tolist()) - colliding)
            if model.mesh_facenum[m] > budget and model.mesh_texcoordnum[m] == 0
            and model.mesh_normalnum[m] >= model.mesh_vertnum[m]]


def mesh_arrays(model: mujoco.MjModel, mesh: int) -> tuple[np.ndarray, np.ndarray]:
    """The compiled vertices and faces of ``mesh``."""
    va, vn = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    fa, fn = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
    return model.mesh_vert[va:va + vn].copy(), model.mesh_face[fa:fa + fn].copy()


def _write_mesh(model: mujoco.MjModel, mesh: int, simple: SimpleMesh) -> None:
    va, na, fa = model.mesh_vertadr[mesh], model.mesh_normaladr[mesh], model.mesh_faceadr[mesh]
    nv, nf = len(simple.vertices), len(simple.faces)
    model.mesh_vert[va:va + nv] = simple.vertices
    model.mesh_normal[na:na + nv] = simple.normals
    model.mesh_face[fa:fa + nf] = simple.faces
    model.mesh_facenormal[fa:fa + nf] = simple.faces  # one normal per vertex
    model.mesh_vertnum[mesh] = model.mesh_normalnum[mesh] = nv
    model.mesh_facenum[mesh] = nf


def mesh_key(vertices: np.ndarray, faces: np.ndarray, budget: int) -> str:
    digest = hashlib.sha1(f"{VERSION}:{budget}:{vertices.shape}:{faces.shape}".encode())
    digest.update(np.ascontiguousarray(vertices, np.float32).tobytes())
    digest.update(np.ascontiguousarray(faces, np.int32).tobytes())
    return digest.hexdigest()[:16]


_MEMO: dict[str, SimpleMesh] = {}  # this process's simplified meshes, by key


def simplified(vertices: np.ndarray, faces: np.ndarray, budget: int = FACE_BUDGET) -> SimpleMesh:
    """``(vertices, faces)`` simplified to at most ``budget`` faces, from the cache when it holds
    them, else computed and stored (a read-only cache directory only costs the recomputation)."""
    key = mesh_key(vertices, faces, budget)
    if key in _MEMO:
        return _MEMO[key]
    path = cache_dir() / f"mesh-lod-{key}.npz"
    mesh = _read(path, budget)
    if mesh is None:
        mesh = simplify(vertices, faces, budget)
        with contextlib.suppress(OSError):
            _write(path, mesh)
    _MEMO[key] = mesh
    return mesh


def simplify(vertices: np.ndarray, faces: np.ndarray, budget: int) -> SimpleMesh:
    """Quadric edge-collapse decimation of a triangle mesh to at most ``budget`` faces."""
    if budget < 4:
        raise ConfigError(f"a face budget of {budget} cannot keep a closed mesh; use at least 4")
    try:
        import fast_simplification
    except ImportError:  # a dependency of vcage; missing only in a broken environment
        raise ConfigError("simplified meshes need the fast-simplification package: "
                          "`pip install fast-simplification`, or render with mesh_detail='full'") from None
    v, f = vertices.astype(np.float64), faces.astype(np.int32)
    target = budget
    while len(f) > budget:  # the decimator may stop a little above its target: aim lower
        if target < 4:
            raise ConfigError(f"could not simplify a mesh of {len(faces)} faces to {budget}; "
                              "render with mesh_detail='full'")
        v, f = fast_simplification.simplify(vertices.astype(np.float64), faces.astype(np.int32),
                                            target_count=target)
        target -= max(1, len(f) - budget)
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]  # no degenerate faces
    used, inverse = np.unique(f, return_inverse=True)  # and no unused vertices
    v, f = v[used], inverse.reshape(-1, 3).astype(np.int32)
    return SimpleMesh(v.astype(np.float32), f, _vertex_normals(v, f))


def _vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted vertex normals (as MuJoCo computes them for meshes without normals)."""
    tri = vertices[faces]
    face_normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals = np.zeros_like(vertices)
    for corner in range(3):
        np.add.at(normals, faces[:, corner], face_normals)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return (normals / np.where(length > 0, length, 1.0)).astype(np.float32)


def _read(path: Path, budget: int) -> SimpleMesh | None:
    """The cached mesh at ``path``, or None when there is none or it is not a valid mesh."""
    try:
        with np.load(path) as data:
            mesh = SimpleMesh(data["vertices"], data["faces"], data["normals"])
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile):  # missing or corrupt
        return None
    v, f, n = mesh.vertices, mesh.faces, mesh.normals
    valid = (v.ndim == 2 and v.shape[1] == 3 and v.dtype == np.float32 and n.shape == v.shape
             and n.dtype == np.float32 and f.ndim == 2 and f.shape[1] == 3 and f.dtype == np.int32
             and 0 < len(f) <= budget and f.min() >= 0 and f.max() < len(v)
             and bool(np.isfinite(v).all()) and bool(np.isfinite(n).all()))
    return mesh if valid else None


def _write(path: Path, mesh: SimpleMesh) -> None:
    """Store ``mesh`` atomically, so that concurrent workers never read half a file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.stem, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            np.savez(fh, vertices=mesh.vertices, faces=mesh.faces, normals=mesh.normals)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
