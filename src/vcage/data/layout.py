"""Every path of a dataset on disk, in one place: LeRobot v3's files and vcage's own.

LeRobot's path templates are formatted with ``chunk_index``/``file_index`` (and ``video_key``);
vcage's extras with ``episode_index``. Nothing else in vcage spells a dataset path.
"""

from __future__ import annotations

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
LOCK_PATH = "meta/.vcage.lock"  # held by the one writer appending
ATTEMPTS_LOG = "meta/vcage_attempts.jsonl"  # every attempt, accepted or not, with its oracle audit
EXTRAS_PATH = "extras/episode_{episode_index:06d}.json"  # seed, plan, scene, verdicts of an episode
ARRAYS_PATH = "extras/episode_{episode_index:06d}_states.npz"  # simulator states for exact replay
FUNNEL_PATH = "stats.json"  # the last generation run's funnel
