"""Every path of a dataset on disk, in one place: LeRobot v3's files and vcage's own.

LeRobot's path templates are formatted with ``chunk_index``/``file_index`` (and ``video_key``);
vcage's extras with ``episode_index``. Nothing else in vcage spells a dataset path.

Episodes are packed as LeRobot packs them: one data file and one video file per camera hold many
consecutive episodes, up to the size limits below; then the next file (``file_index + 1``, or the
next chunk after ``chunks_size`` files) starts. vcage starts the data file and the video files
together, so an episode's data and videos share one (chunk, file) position.
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
# the views the critic judged when it rejected an attempt: one PNG per rejected attempt, named by
# the attempt's sample index and attempt number in the attempt log (``episode``, ``attempt``)
CRITIC_VIEW_PATH = "extras/critic_views/sample_{sample:06d}_attempt_{attempt:03d}.png"
CARD_PATH = "README.md"  # the dataset card, rewritten at each commit
REPAIR_STAGING = ".repair-staging"  # where `vcage verify --repair` builds what it puts in
REPAIR_PLAN = REPAIR_STAGING + "/PLAN.json"  # written when that is complete: the repair is then due

# per-episode provenance columns of meta/episodes (copied from the episode's extras when present)
PROVENANCE = {"vcage/seed": "seed", "vcage/attempt": "attempt", "vcage/oracle_success": "oracle_success"}

# An episode joins the open data and video files unless one would grow past its limit. The data
# limit is LeRobot's default. The video limit is not (LeRobot's is 200 MB): appending rewrites the
# open video file by copying its packets, a cost per frame already in it, and vcage's small frames
# (about 1 KB each at 128x128) would put some 200,000 frames in a 200 MB file; 10 MB holds about
# as many frames as LeRobot's 200 MB of 480x640 video (benchmarks/packing.py measures the cost).
DATA_FILES_SIZE_IN_MB = 100
VIDEO_FILES_SIZE_IN_MB = 10

_FILE = re.compile(r"^(data|videos/(.+))/chunk-(\d+)/file-(\d+)\.(?:parquet|mp4)$")
_EXTRAS = re.compile(r"^extras/episode_(\d+)(?:_states\.npz|\.json)$")


def file_position(rel: str) -> tuple[str, tuple[int, int]] | None:
    """``("data" or the camera key, (chunk, file))`` of a data or video file, else None.

    ``rel`` is the path relative to the dataset root, with ``/`` separators.
    """
    match = _FILE.match(rel)
    if match is None:
        return None
    kind, camera, chunk, file = match.groups()
    return (camera if camera is not None else kind), (int(chunk), int(file))


def row_position(row: dict, key: str) -> tuple[int, int]:
    """Where a ``meta/episodes`` row puts its episode in the data (``key="data"``) or a camera's
    video files: (chunk, file). KeyError if the row lacks the columns."""
    prefix = "data" if key == "data" else f"videos/{key}"
    return int(row[f"{prefix}/chunk_index"]), int(row[f"{prefix}/file_index"])


def next_position(position: tuple[int, int], chunks_size: int) -> tuple[int, int]:
    """The file after ``position``: the next file index, or the next chunk's first file."""
    chunk, file = position
    return (chunk, file + 1) if file + 1 < chunks_size else (chunk + 1, 0)


def extras_episode(rel: str) -> int | None:
    """The episode an ``extras/`` file (JSON or states) belongs to, else None."""
    match = _EXTRAS.match(rel)
    return int(match.group(1)) if match is not None else None
