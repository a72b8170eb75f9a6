"""Every path of a dataset on disk, in one place: LeRobot v3's files and vcage's own.

LeRobot's path templates are formatted with ``chunk_index``/``file_index`` (and ``video_key``);
vcage's extras with ``episode_index``. Nothing else in vcage spells a dataset path.
"""

from __future__ import annotations

import re

CODEBASE_VERSION = "v3.0"
CHUNKS_SIZE = 1000

# LeRobot v3
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
EPISODES_PATH = "meta/episodes/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
INFO_PATH = "meta/info.json"
TASKS_PATH = "meta/tasks.parquet"
STATS_PATH = "meta/stats.json"

# vcage
VCAGE_PATH = "meta/vcage.json"  # format marker and the configuration the dataset was made with
LEGACY_LOCK_PATH = "meta/.vcage.lock"  # older writers locked this file; the directory is locked now
ATTEMPTS_LOG = "meta/vcage_attempts.jsonl"  # every attempt, accepted or not, with its oracle audit
EXTRAS_PATH = "extras/episode_{episode_index:06d}.json"  # seed, plan, scene, verdicts of an episode
ARRAYS_PATH = "extras/episode_{episode_index:06d}_states.npz"  # simulator states for exact replay
RUNS_LOG = "meta/vcage_runs.jsonl"  # one line per generation run: its funnel (attempts, stages, time)
CARD_PATH = "README.md"  # the dataset card, rewritten at each commit

# per-episode provenance columns of meta/episodes (copied from the episode's extras when present)
PROVENANCE = {"vcage/seed": "seed", "vcage/attempt": "attempt", "vcage/oracle_success": "oracle_success"}

_EPISODE_FILE = re.compile(
    r"^(?:data|videos/.+)/chunk-(\d+)/file-(\d+)\.(?:parquet|mp4)$|^extras/episode_(\d+)(?:_states\.npz|\.json)$")


def episode_of_file(rel: str, chunks_size: int) -> int | None:
    """The episode index a vcage-written episode file belongs to (one episode per file), or None.

    ``rel`` is the path relative to the dataset root, with ``/`` separators.
    """
    match = _EPISODE_FILE.search(rel)
    if match is None:
        return None
    chunk, file, ep = match.groups()
    return int(ep) if ep is not None else int(chunk) * chunks_size + int(file)
