"""What each episode of a dataset holds, read as a user's reader would, for tests that check a repair
kept an episode unchanged: every value column but the three a renumbering changes (episode_index,
index, task_index), its task, every decoded frame of each camera, its extras and states files."""

from __future__ import annotations

from pathlib import Path

from vcage.data import DatasetReader
from vcage.data.layout import ARRAYS_PATH, EXTRAS_PATH

RENUMBERED = ("episode_index", "index", "task_index")


def episode_content(reader: DatasetReader, i: int) -> dict[str, object]:
    episode = reader.episode(i)
    out: dict[str, object] = {f"data/{k}": v.tobytes() for k, v in episode.frames.items()
                              if k not in RENUMBERED}
    out["task"] = reader.episode_meta(i)["tasks"]
    for key in reader.cameras if reader.videos else ():
        out[key] = reader.video(i, key).tobytes()
    for template in (EXTRAS_PATH, ARRAYS_PATH):
        path = reader.root / template.format(episode_index=i)
        out[template] = path.read_bytes() if path.is_file() else None
    return out


def contents_by_episode(root: Path) -> list[dict[str, object]]:
    reader = DatasetReader(root)
    return [episode_content(reader, i) for i in range(reader.num_episodes)]
