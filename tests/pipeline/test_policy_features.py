"""What a policy learns from and is evaluated in: the environment state and subtask index of
generated datasets, their back-fill into older datasets, and the goal evaluation environment,
whose observations are the dataset's own frames when it replays an episode."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest
from gymnasium.error import ResetNeeded

from vcage.config import RenderConfig
from vcage.data import DatasetReader, verify
from vcage.data import columns as columns_mod
from vcage.data.layout import INFO_PATH, STATS_PATH, VCAGE_PATH
from vcage.errors import ConfigError, DatasetError
from vcage.pipeline.backfill import backfill
from vcage.pipeline.config import SEED_LIMIT, GenerateConfig
from vcage.pipeline.evaluation import make_env
from vcage.pipeline.features import ACTION, ACTION_EE, ENVIRONMENT, SUBTASK
from vcage.pipeline.generate import generate
from vcage.scene.instantiate import SceneConfig

GOAL = "put the mouse on the pad, then press the bell"
CFG = GenerateConfig(scene=SceneConfig(clutter=1), render=RenderConfig(size=(64, 64), cameras=("front",)),
                     critic=None, seed=5)
OBSERVED = ("observation.state", "observation.ee_pose", ENVIRONMENT)


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("features") / "ds"
    funnel = generate(GOAL, 2, out, CFG)
    assert funnel.dataset_episodes == 2
    return out


@pytest.fixture()
def ds(made: Path, tmp_path: Path) -> Path:
    shutil.copytree(made, tmp_path / "ds")
    return tmp_path / "ds"


def strip(root: Path, keys: tuple[str, ...] = (ENVIRONMENT, SUBTASK, ACTION_EE)) -> None:
    """Make ``root`` what an older version wrote: without the features ``keys``."""
    for path in (root / "data").rglob("*.parquet"):
        table = pq.read_table(path)
        pq.write_table(table.drop_columns([k for k in keys if k in table.column_names]), path)
    for path in (root / "meta/episodes").rglob("*.parquet"):
        table = pq.read_table(path)
        pq.write_table(table.drop_columns([c for c in table.column_names  # nor the content digests then
                                           if any(c.startswith(f"stats/{k}/") for k in keys)
                                           or c.startswith("vcage/sha256/")]), path)
    info = json.loads((root / INFO_PATH).read_text())
    info["features"] = {k: v for k, v in info["features"].items() if k not in keys}
    (root / INFO_PATH).write_text(json.dumps(info))
    marker = json.loads((root / VCAGE_PATH).read_text())
    marker["info"]["features"] = info["features"]
    marker.pop("schema", None)  # schema 1: rows without content digests
    (root / VCAGE_PATH).write_text(json.dumps(marker))
    stats = json.loads((root / STATS_PATH).read_text())
    (root / STATS_PATH).write_text(json.dumps({k: v for k, v in stats.items() if k not in keys}))


def frames(root: Path) -> list[dict[str, Any]]:
    reader = DatasetReader(root)
    return [reader.episode(i).frames for i in range(reader.num_episodes)]


def test_a_generated_dataset_holds_object_poses_and_subtask_indices(made: Path) -> None:
    reader = DatasetReader(made)
    names = reader.features[ENVIRONMENT].names
    plan_objects = [o["name"] for o in reader.config["plan"]["objects"]]
    assert names is not None and list(names[:7]) == [f"{plan_objects[0]}.{c}" for c in
                                                      ("x", "y", "z", "qw", "qx", "qy", "qz")]
    assert reader.features[ENVIRONMENT].shape == (7 * len(plan_objects),)
    for i in range(2):
        ep = reader.episode(i)
        env = ep.frames[ENVIRONMENT].reshape(ep.length, -1, 7)
        assert np.allclose(np.linalg.norm(env[..., 3:], axis=-1), 1.0, atol=1e-5) and (env[..., 3] >= 0).all()
        index = ep.frames[SUBTASK].ravel()
        bounds = [s["frames"] for s in ep.extras["subtasks"]]
        assert [int(index[start]) for start, _ in bounds] == list(range(len(bounds)))
        assert (np.diff(index) >= 0).all() and index[-1] == len(bounds) - 1
        mouse = plan_objects.index("mouse") if "mouse" in plan_objects else 0
        moved = np.linalg.norm(env[-1, mouse, :3] - env[0, mouse, :3])
        assert moved > 0.02  # the object the first subtask carries moves in its pose


def test_replaying_an_episode_in_the_evaluation_env_gives_its_frames_and_success(made: Path) -> None:
    reader = DatasetReader(made)
    ep = reader.episode(1)
    env = make_env(reader.config, seed=0)
    obs, info = env.reset(options={"scene_seed": ep.extras["seed"]})
    assert info["subtasks"] == 2 and info["subtasks_done"] == 0
    done = []
    for t in range(ep.length):
        for key in OBSERVED:  # the stored actions are float32: contacts amplify that to ~1e-4 here
            np.testing.assert_allclose(obs[key], ep.frames[key][t], atol=1e-3, err_msg=f"{key} at frame {t}")
        obs, reward, terminated, truncated, info = env.step(ep.frames["action"][t])
        done.append(info["subtasks_done"])
        if terminated:
            break
    assert info["success"] and reward == 1.0 and info["progress"] == 1.0
    first_end = ep.extras["subtasks"][0]["frames"][1]
    assert done.index(1) < first_end  # the first subtask is judged done within its own frames
    with pytest.raises(ResetNeeded):
        env.step(ep.frames["action"][-1])


def test_an_episode_started_at_a_later_subtask_continues_the_demonstration_from_there(made: Path) -> None:
    reader = DatasetReader(made)
    ep = reader.episode(0)
    start = ep.extras["subtasks"][1]["frames"][0]
    env = make_env(reader.config, seed=0)
    obs, info = env.reset(options={"scene_seed": ep.extras["seed"], "state": ep.arrays["states"][start],
                                   "subtask": 1})
    assert info["subtasks_done"] == 1 and not info["success"]
    assert env.unwrapped.holds(0)  # the mouse lies on its pad
    for key in OBSERVED:
        np.testing.assert_allclose(obs[key], ep.frames[key][start], atol=1e-5, err_msg=key)
    for t in range(start, ep.length):  # the rest of the demonstration completes the plan
        obs, reward, terminated, truncated, info = env.step(ep.frames["action"][t])
        if terminated:
            break
    assert info["success"] and reward == 1.0
    # from the same state judged from subtask 0, holding still completes nothing: the mouse's
    # subtask is judged again (it holds: the mouse lies on its pad) and the bell's is not done
    env.reset(options={"scene_seed": ep.extras["seed"]})
    assert not env.unwrapped.holds(0)  # at the scene's start the mouse lies elsewhere
    env.reset(options={"scene_seed": ep.extras["seed"], "state": ep.arrays["states"][start]})
    for _ in range(12):
        obs, _, terminated, _, info = env.step(np.append(obs["observation.state"][:7], 1.0))
    assert info["subtasks_done"] == 1 and not terminated
    with pytest.raises(ConfigError, match="options\\['state'\\] too"):
        env.reset(options={"subtask": 1})
    with pytest.raises(ConfigError, match="scene_seed"):
        env.reset(options={"state": ep.arrays["states"][start]})
    state = ep.arrays["states"][start]
    with pytest.raises(ConfigError, match="from 0 to 1"):
        env.reset(options={"scene_seed": ep.extras["seed"], "state": state, "subtask": 2})
    with pytest.raises(ConfigError, match="finite numbers"):
        env.reset(options={"scene_seed": ep.extras["seed"], "state": state[:-3]})


def test_evaluation_scenes_are_never_training_scenes_and_repeat_by_seed(made: Path) -> None:
    reader = DatasetReader(made)
    env = make_env(reader.config, seed=3, max_steps=4)
    seeds, starts = [], []
    for _ in range(3):
        obs, info = env.reset()
        seeds.append(info["scene_seed"])
        starts.append(obs[ENVIRONMENT])
    assert all(s >= SEED_LIMIT for s in seeds) and len(set(seeds)) == 3  # generation seeds are below
    obs, info = env.reset(seed=3)
    assert info["scene_seed"] == seeds[0] and np.array_equal(obs[ENVIRONMENT], starts[0])
    hold = obs["observation.state"].copy()
    hold[7] = 1.0
    for _ in range(4):
        obs, reward, terminated, truncated, info = env.step(hold)
    assert truncated and not terminated and not info["success"]
    assert env.observation_space.contains(obs)


def test_replaying_the_tool_poses_through_ik_completes_the_episode_on_the_demonstrated_path(
        made: Path) -> None:
    reader = DatasetReader(made)
    ep = reader.episode(0)
    tool, pose = ep.frames[ACTION_EE], ep.frames["observation.ee_pose"]
    assert tuple(reader.features[ACTION_EE].names or ()) == ("x", "y", "z", "qw", "qx", "qy", "qz", "gripper")
    np.testing.assert_array_equal(tool[:, 7], ep.frames[ACTION][:, 7])
    held = np.r_[False, np.linalg.norm(np.diff(ep.frames[ACTION][:, :7], axis=0), axis=1) == 0]
    run = np.zeros(len(held), dtype=int)  # for how many frames the arm has held its target
    for t in range(1, len(held)):
        run[t] = run[t - 1] + 1 if held[t] else 0
    still = int(np.argmax(run))  # the end of the longest hold: the hand has reached the target
    assert run[still] >= 5
    assert np.linalg.norm(tool[still, :3] - pose[still, :3]) < 0.003  # it is where the action's pose says
    env = make_env(reader.config, seed=0, action=ACTION_EE)
    assert env.action_space.shape == (8,)
    assert tuple(env.features[ACTION_EE].names) == tuple(reader.features[ACTION_EE].names or ())
    obs, info = env.reset(options={"scene_seed": ep.extras["seed"]})
    gap = []
    for t in range(ep.length):
        gap.append(np.linalg.norm(obs["observation.ee_pose"][:3] - pose[t, :3]))
        obs, reward, terminated, truncated, info = env.step(tool[t])
        if terminated:
            break
    assert info["success"] and reward == 1.0
    assert np.median(gap) < 0.002 and max(gap) < 0.05  # the hand follows the demonstration's path
    env.reset()
    with pytest.raises(ValueError, match="quaternion"):
        env.step(np.r_[0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    with pytest.raises(ConfigError, match="unknown action 'torque'"):
        make_env(reader.config, action="torque")


def test_the_evaluation_env_refuses_bad_input(made: Path) -> None:
    env = make_env(DatasetReader(made).config, seed=0, max_steps=10)
    with pytest.raises(ResetNeeded):
        env.step(np.zeros(8))
    env.reset()
    with pytest.raises(ValueError, match="8 finite"):
        env.step(np.full(8, np.nan))
    with pytest.raises(ValueError, match="8 finite"):
        env.step(np.zeros(5))
    with pytest.raises(ConfigError, match="meta/vcage.json"):
        make_env({"k": 1})
    with pytest.raises(ConfigError, match="max_steps"):
        make_env(DatasetReader(made).config, max_steps=0)


def test_backfill_gives_an_older_dataset_the_features_generation_writes(ds: Path, made: Path) -> None:
    strip(ds)
    assert ENVIRONMENT not in DatasetReader(ds).features
    assert backfill(ds) == [ENVIRONMENT, SUBTASK, ACTION_EE]
    for new, original in zip(frames(ds), frames(made), strict=True):
        for key in (ENVIRONMENT, SUBTASK, ACTION_EE):
            np.testing.assert_array_equal(new[key], original[key])
    assert DatasetReader(ds).features == DatasetReader(made).features
    assert json.loads((ds / STATS_PATH).read_text())[ENVIRONMENT] == json.loads(
        (made / STATS_PATH).read_text())[ENVIRONMENT]
    assert verify(ds).ok
    assert backfill(ds) == []  # nothing left to add
    funnel = generate(GOAL, 3, ds, CFG, total=True)  # the same configuration appends again
    assert funnel.dataset_episodes == 3 and verify(ds).ok


def test_an_interrupted_backfill_leaves_the_dataset_as_it_was_and_completes_on_rerun(
        ds: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    strip(ds)
    before = DatasetReader(ds).features

    def crash(*args: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(columns_mod, "_commit", crash)  # after the data files got their columns
    with pytest.raises(KeyboardInterrupt):
        backfill(ds)
    assert DatasetReader(ds).features == before and verify(ds).ok
    monkeypatch.undo()
    assert backfill(ds) == [ENVIRONMENT, SUBTASK, ACTION_EE] and verify(ds).ok
    assert [f[SUBTASK].max() for f in frames(ds)] == [1, 1]


def test_backfill_refuses_what_it_cannot_rebuild_and_changes_nothing(ds: Path, tmp_path: Path) -> None:
    strip(ds)
    (ds / "extras/episode_000001_states.npz").unlink()
    info = (ds / INFO_PATH).read_bytes()
    with pytest.raises(DatasetError, match="episode 1 lacks its stored states"):
        backfill(ds)
    assert (ds / INFO_PATH).read_bytes() == info
    marker = json.loads((ds / VCAGE_PATH).read_text())
    (ds / VCAGE_PATH).write_text(json.dumps({**marker, "config": {"task": "x"}}))
    with pytest.raises(DatasetError, match="not made by `vcage generate`"):
        backfill(ds)


def test_an_environment_given_held_out_scenes_builds_exactly_those(made: Path) -> None:
    config = DatasetReader(made).config
    chosen = [make_env(config, seed=9, max_steps=2).reset()[1]["scene_seed"] for _ in range(1)]
    chosen.append(make_env(config, seed=10, max_steps=2).reset()[1]["scene_seed"])
    env = make_env(config, seed=0, max_steps=2, scenes=chosen)
    assert [env.reset()[1]["scene_seed"] for _ in range(3)] == [chosen[0], chosen[1], chosen[0]]
    with pytest.raises(ConfigError, match="scenes"):
        make_env(config, scenes=[])


def test_an_objects_pose_is_read_where_the_environment_state_names_it() -> None:
    from vcage.pipeline.features import ENVIRONMENT, dataset_features, pose_slice
    from vcage.planning.offline import OfflinePlanner

    plan = OfflinePlanner().plan("put the mouse on the pad, then press the bell")
    names = dataset_features(plan)[ENVIRONMENT].names
    for obj in ("mouse", "bell"):
        pose = [f"{obj}.{c}" for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]
        assert list(names[pose_slice(plan, obj)]) == pose
