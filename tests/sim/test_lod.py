"""Simplified visual meshes: cached by content and budget, drawn only, close to the full ones."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from vcage.config import RenderConfig
from vcage.errors import ConfigError
from vcage.sim import lod
from vcage.sim.render import ROBOT, Renderer
from vcage.sim.world import World


@pytest.fixture()
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty disk cache and an empty in-process memo."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(lod, "_MEMO", {})
    return tmp_path / "vcage"


def _sphere(radius: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=radius)  # 1,280 faces
    return mesh.vertices.astype(np.float32), mesh.faces.astype(np.int32)


def _count_simplify(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    calls: list[int] = []
    original = lod.simplify

    def counted(vertices: np.ndarray, faces: np.ndarray, budget: int) -> lod.SimpleMesh:
        calls.append(budget)
        return original(vertices, faces, budget)

    monkeypatch.setattr(lod, "simplify", counted)
    return calls


def test_cache_is_keyed_by_the_mesh_and_the_budget(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = _count_simplify(monkeypatch)
    vertices, faces = _sphere()
    first = lod.simplified(vertices, faces, 200)
    assert calls == [200] and len(list(cache.glob("mesh-lod-*.npz"))) == 1
    monkeypatch.setattr(lod, "_MEMO", {})  # a new process: only the disk cache is left
    again = lod.simplified(vertices, faces, 200)
    assert calls == [200]  # read from the disk cache, not recomputed
    np.testing.assert_array_equal(again.faces, first.faces)
    np.testing.assert_array_equal(again.vertices, first.vertices)
    moved = vertices * np.float32(1.5)  # another source mesh
    lod.simplified(moved, faces, 200)
    lod.simplified(vertices, faces, 300)  # another budget
    assert calls == [200, 200, 300] and len(list(cache.glob("mesh-lod-*.npz"))) == 3


def test_simplified_meshes_keep_the_budget(cache: Path) -> None:
    vertices, faces = _sphere()
    for budget, tolerance in ((50, 0.01), (200, 0.004), (1000, 0.001)):
        mesh = lod.simplified(vertices, faces, budget)
        assert 0.8 * budget <= len(mesh.faces) <= budget
        assert mesh.faces.min() >= 0 and mesh.faces.max() < len(mesh.vertices)
        np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-5)
        # a sphere stays a sphere (its 1,280 faces to 50: every vertex within 10% of the radius)
        assert np.abs(np.linalg.norm(mesh.vertices, axis=1) - 0.1).max() < tolerance


def test_robot_meshes_are_simplified_to_the_budget(world: World) -> None:
    full = world.model
    heavy = lod.heavy_visual_meshes(full, lod.FACE_BUDGET)
    assert {full.mesh(m).name for m in heavy} >= {f"panda/link{i}_viz" for i in range(8)}
    simple = lod.lod_model(full)
    assert full.mesh_facenum.sum() > 130_000 > 20_000 > simple.mesh_facenum.sum()
    quality = (simple.vis.quality.numslices, simple.vis.quality.numstacks, simple.vis.quality.numquads)
    assert quality == lod.LOD_QUALITY != (full.vis.quality.numslices, full.vis.quality.numstacks,
                                          full.vis.quality.numquads)  # the drawn copy only
    for m in heavy:
        assert simple.mesh_facenum[m] <= lod.FACE_BUDGET < full.mesh_facenum[m]
        _, faces = lod.mesh_arrays(simple, m)
        assert faces.min() >= 0 and faces.max() < simple.mesh_vertnum[m]


def test_corrupt_cache_files_are_rebuilt(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    vertices, faces = _sphere()
    path = cache / f"mesh-lod-{lod.mesh_key(vertices, faces, 200)}.npz"
    cache.mkdir(parents=True)
    bad_faces = np.full((10, 3), 10_000, np.int32)  # indices past the vertices
    with path.open("wb") as fh:
        np.savez(fh, vertices=vertices, faces=bad_faces, normals=vertices)
    for corrupt in (b"not a zip file", path.read_bytes()[:100], path.read_bytes()):
        path.write_bytes(corrupt)
        monkeypatch.setattr(lod, "_MEMO", {})
        mesh = lod.simplified(vertices, faces, 200)
        assert len(mesh.faces) <= 200 and mesh.faces.max() < len(mesh.vertices)
        with np.load(path) as stored:  # overwritten with the good mesh
            np.testing.assert_array_equal(stored["faces"], mesh.faces)


def test_lod_changes_only_what_is_drawn(world: World) -> None:
    full = world.model
    faces_before = int(full.mesh_facenum.sum())
    simple = lod.lod_model(full)
    assert simple is not full and int(full.mesh_facenum.sum()) == faces_before  # physics untouched
    for name in ("nq", "nv", "nu", "nbody", "njnt", "ngeom", "nmesh", "nmeshvert", "nmeshface"):
        assert getattr(simple, name) == getattr(full, name), name
    for name in ("body_mass", "body_inertia", "body_pos", "body_quat", "jnt_range", "dof_damping",
                 "geom_type", "geom_contype", "geom_conaffinity", "geom_pos", "geom_quat",
                 "geom_dataid", "geom_group", "actuator_gainprm"):
        np.testing.assert_array_equal(getattr(simple, name), getattr(full, name), err_msg=name)
    planes = full.geom_type == int(mujoco.mjtGeom.mjGEOM_PLANE)  # a plane's third size is its drawn grid
    assert planes.any() and np.all(simple.geom_size[planes, 2] >= lod.PLANE_GRID)
    np.testing.assert_array_equal(simple.geom_size[planes, :2], full.geom_size[planes, :2])
    np.testing.assert_array_equal(simple.geom_size[~planes], full.geom_size[~planes])
    changed = np.nonzero(simple.mesh_facenum != full.mesh_facenum)[0]
    assert len(changed) >= 8
    mesh_geoms = full.geom_type == int(mujoco.mjtGeom.mjGEOM_MESH)
    for m in range(full.nmesh):
        users = np.nonzero(mesh_geoms & (full.geom_dataid == m))[0]
        collides = bool(np.any((full.geom_contype[users] != 0) | (full.geom_conaffinity[users] != 0)))
        if collides:  # a collision mesh is the full one, vertex for vertex
            assert m not in changed
            np.testing.assert_array_equal(lod.mesh_arrays(simple, m)[1], lod.mesh_arrays(full, m)[1])
        if m in changed:
            assert len(users) > 0 and not collides
    for budget in (10, 100):  # whatever the budget, a mesh that collides is never simplified
        for m in lod.heavy_visual_meshes(full, budget):
            users = mesh_geoms & (full.geom_dataid == m)
            assert not np.any(full.geom_contype[users] | full.geom_conaffinity[users])
    data = mujoco.MjData(simple)  # same kinematics: the same posture puts the bodies in the same places
    data.qpos[:] = world.data.qpos
    mujoco.mj_kinematics(simple, data)
    np.testing.assert_array_equal(data.xpos, world.data.xpos)


def _robot_iou(a: np.ndarray, b: np.ndarray) -> float:
    ra, rb = a == ROBOT, b == ROBOT
    return float((ra & rb).sum() / max(1, (ra | rb).sum()))


def test_lod_frames_are_close_to_full_frames(world: World, cache: Path) -> None:
    rng = np.random.default_rng(0)
    limits = world.robot.arm_limits
    home = world.get_state()
    states = [home]
    for _ in range(3):
        world.data.qpos[world.robot.arm_qpos] = rng.uniform(limits[:, 0], limits[:, 1])
        states.append(world.get_state())
    mads = []
    # measured: robot IoU 0.957-1.0, mean absolute difference 0.0-3.1 (a wrist view grazing a
    # link), 0.6 on average, over these 12 frames
    with Renderer(world, 128, 128, "full") as full, Renderer(world, 128, 128, "lod") as simple:
        for state in states:
            world.show_state(state)
            for cam in ("front", "panda/wrist", "top"):
                iou = _robot_iou(full.segmentation(cam), simple.segmentation(cam))
                mads.append(np.abs(full.rgb(cam).astype(int) - simple.rgb(cam).astype(int)).mean())
                assert iou > 0.95 and mads[-1] < 4.0, (cam, iou, mads[-1])
    assert np.mean(mads) < 1.0


def test_mesh_detail_is_checked_and_stored(world: World) -> None:
    assert RenderConfig().mesh_detail == "lod"
    cfg = RenderConfig(mesh_detail="full")
    assert RenderConfig.from_dict(cfg.to_dict()) == cfg
    with pytest.raises(ConfigError, match="unknown mesh_detail 'medium'; choose one of full, lod"):
        RenderConfig(mesh_detail="medium")
    with pytest.raises(ConfigError, match="mesh_detail"):
        RenderConfig.from_dict({"mesh_detail": "high"})
    with pytest.raises(ConfigError, match="unknown mesh detail 'high'"):
        Renderer(world, 64, 64, "high")
    with Renderer(world, 64, 64, "full") as r:
        assert r.model is world.model
