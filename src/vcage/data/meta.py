"""The meta files a dataset writer rewrites with each episode: ``meta/info.json``, the vcage marker
``meta/vcage.json``, the tasks, the episodes file, the stats and the dataset card."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from vcage.data import layout, video
from vcage.data import stats as st
from vcage.data.card import dataset_card
from vcage.data.files import episodes_table, tasks_table, write_json, write_table
from vcage.data.reader import STANDARD_COLUMNS, Feature
from vcage.data.schema import SCHEMA


class _MetaFiles:
    """The meta files of :class:`vcage.data.lerobot.DatasetWriter`, from its configuration."""

    root: Path
    fps: int
    robot_type: str
    chunks_size: int
    file_mb: dict[str, float]
    features: dict[str, Feature]
    cameras: dict[str, tuple[int, int]]
    config: dict[str, Any]
    _encoder: str

    def _info(self, episodes: int, frames: int, tasks: int) -> dict[str, Any]:
        features: dict[str, Any] = {k: f.to_info() for k, f in self.features.items()}
        codec = video.codec_name(self._encoder) if self._encoder else None
        for key, (h, w) in self.cameras.items():
            features[key] = {"dtype": "video", "shape": [h, w, 3], "names": ["height", "width", "channels"],
                             "info": {"video.height": h, "video.width": w, "video.codec": codec,
                                      "video.pix_fmt": video.PIX_FMT, "video.is_depth_map": False,
                                      "video.fps": self.fps, "video.channels": 3, "has_audio": False}}
        for key, dtype in STANDARD_COLUMNS.items():
            features[key] = {"dtype": dtype, "shape": [1], "names": None}
        info = {"codebase_version": layout.CODEBASE_VERSION, "robot_type": self.robot_type,
                "total_episodes": episodes, "total_frames": frames, "total_tasks": tasks,
                "chunks_size": self.chunks_size,
                "data_files_size_in_mb": _number(self.file_mb["data"]),
                "video_files_size_in_mb": _number(self.file_mb["video"]), "fps": self.fps,
                "splits": {"train": f"0:{episodes}"}, "data_path": layout.DATA_PATH,
                "video_path": layout.VIDEO_PATH if self.cameras else None, "features": features}
        return info

    def _write_info(self, episodes: int, frames: int, tasks: int) -> None:
        write_json(self.root / layout.INFO_PATH, self._info(episodes, frames, tasks))

    def _card(self, episodes: int, frames: int, tasks: list[str]) -> str:
        return dataset_card(self._info(episodes, frames, len(tasks)), tasks)

    def _write_marker(self) -> None:
        """``meta/vcage.json``: the format, the config, and ``meta/info.json`` without its totals (so
        that :func:`vcage.data.repair.repair` can rebuild a damaged ``info.json``)."""
        static = {k: v for k, v in self._info(0, 0, 0).items()
                  if k not in ("total_episodes", "total_frames", "total_tasks", "splits")}
        write_json(self.root / layout.VCAGE_PATH, {"format": "vcage/lerobot-v3", "schema": SCHEMA,
                                                   "config": self.config, "info": static})

    def _write_meta(self, tasks: list[str], chunk_rows: list[dict[str, Any]],
                    stats: dict[str, dict[str, np.ndarray]]) -> None:
        """tasks.parquet, the episodes file of ``chunk_rows`` and stats.json (not yet the commit)."""
        write_table(self.root / layout.TASKS_PATH, tasks_table(tasks))
        chunk = chunk_rows[-1]["episode_index"] // self.chunks_size
        write_table(self.root / layout.EPISODES_PATH.format(chunk_index=chunk, file_index=0),
                    episodes_table(chunk_rows))
        write_json(self.root / layout.STATS_PATH, st.to_json(stats))


def _number(value: float) -> int | float:
    """A size for ``meta/info.json``: an integer when it is one (as LeRobot writes its defaults)."""
    return int(value) if float(value).is_integer() else value
