"""An accepted episode as the report shows it: its subtasks with the critic's verdict beside the
oracle's predicates, keyframes at every subtask boundary from each camera, and a clip.

Everything is read through :class:`~vcage.data.DatasetReader` (extras and decoded videos).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from vcage.data import DatasetReader
from vcage.errors import CorruptDatasetError
from vcage.report.media import clip_uri, png_uri


@dataclass(frozen=True)
class SubtaskEvidence:
    index: int
    description: str
    skill: str
    frames: tuple[int, int]  # [start, end) in the episode
    critic_accept: bool | None  # None: no critic judged it (Vanilla)
    critic_reason: str
    oracle: dict[str, bool]  # predicate -> value, held at the end of the subtask
    oracle_success: bool

    @property
    def disagrees(self) -> bool:
        return self.critic_accept is not None and self.critic_accept != self.oracle_success


@dataclass(frozen=True)
class Keyframe:
    label: str  # "start", or "after subtask i"
    frame: int
    images: dict[str, str]  # camera key -> PNG data URI


@dataclass(frozen=True)
class EpisodeEvidence:
    index: int
    length: int
    seed: int | None
    sample: int | None  # the attempt log's sample index
    attempt: int | None  # which attempt of the sample was accepted
    task: str
    oracle_success: bool
    subtasks: tuple[SubtaskEvidence, ...]
    keyframes: tuple[Keyframe, ...] = ()  # empty when only listed, not shown
    clip: str | None = None  # animated WebP data URI
    clip_fps: float = 0.0
    cameras: tuple[str, ...] = field(default_factory=tuple)

    @property
    def disagrees(self) -> bool:
        return any(s.disagrees for s in self.subtasks)


def subtasks(extras: dict[str, Any]) -> tuple[SubtaskEvidence, ...]:
    """The subtasks of an episode's extras: the critic's verdicts with the oracle's audit."""
    audits = {int(a["subtask"]): a for a in extras.get("oracle_audit", [])}
    out = []
    for sub in extras.get("subtasks", []):
        audit = audits.get(int(sub["index"]), {})
        verdict = sub.get("verdict") or None
        out.append(SubtaskEvidence(
            index=int(sub["index"]), description=str(sub.get("description", "")),
            skill=str(audit.get("skill", "")), frames=(int(sub["frames"][0]), int(sub["frames"][1])),
            critic_accept=bool(verdict["accept"]) if verdict else None,
            critic_reason=str(verdict.get("reason", "")) if verdict else "",
            oracle={str(k): bool(v) for k, v in audit.get("oracle", {}).items()},
            oracle_success=bool(audit.get("oracle_success", False))))
    return tuple(out)


def boundaries(subs: tuple[SubtaskEvidence, ...], length: int) -> list[tuple[str, int]]:
    """(label, frame) at the start and after every subtask, within the episode's frames."""
    last = max(length - 1, 0)
    marks = [("start", min(subs[0].frames[0], last) if subs else 0)]
    marks += [(f"after subtask {s.index + 1}", min(max(s.frames[1] - 1, 0), last)) for s in subs]
    return marks


def episode_evidence(reader: DatasetReader, index: int, media: bool) -> EpisodeEvidence:
    """Episode ``index`` of ``reader``; with ``media`` its keyframes and clip (decodes its videos)."""
    extras = reader.extras(index)
    length = int(reader.episode_meta(index)["length"])
    try:
        subs = subtasks(extras)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise CorruptDatasetError(f"the extras of episode {index} in {reader.root} lack or mangle a "
                                  f"subtask field ({exc!r}); the dataset is corrupt") from exc
    keyframes: tuple[Keyframe, ...] = ()
    clip, clip_fps = None, 0.0
    cameras = tuple(reader.cameras)
    if media and cameras:
        videos = {key: reader.video(index, key) for key in cameras}
        keyframes = tuple(Keyframe(label, frame, {key: png_uri(v[frame]) for key, v in videos.items()})
                          for label, frame in boundaries(subs, length))
        clip, clip_fps = clip_uri([videos[key] for key in cameras], reader.fps)
    tasks = reader.episode_meta(index).get("tasks") or [""]
    return EpisodeEvidence(
        index=index, length=length, seed=_int(extras.get("seed")), sample=_int(extras.get("sample")),
        attempt=_int(extras.get("attempt")), task=str(tasks[0] if isinstance(tasks, list) else tasks),
        oracle_success=bool(extras.get("oracle_success", False)), subtasks=subs,
        keyframes=keyframes, clip=clip, clip_fps=clip_fps, cameras=cameras)


def _int(value: Any) -> int | None:
    return int(value) if isinstance(value, (int, np.integer)) and not isinstance(value, bool) else None
