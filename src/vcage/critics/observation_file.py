"""What a critic was shown, frozen to one file and read back unchanged.

A critic's verdict depends on its :class:`~vcage.critics.base.Observation` alone, so a stored one
judges a changed critic without the physics that made it: tests of the critic read the rollouts
they need from such files, and a patch release of the simulator, which moves chaotic rollouts,
cannot move them. The file is a compressed NumPy archive (no pickle): every array of every view
under ``<moment>/<camera>/<field>``, and one JSON document (``meta``) with the subtask, the labels,
the types, the oracle's values and whatever the writer adds (``extra``: how the rollout was made,
what the oracle said of the subtask). Arrays come back with the dtype and shape they were saved
with, so a critic judges the file exactly as it judged the observation.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from vcage.critics.base import Observation, View
from vcage.errors import DatasetError
from vcage.planning.schema import Subtask

FORMAT = 1  # the layout of the file; a reader refuses another
MOMENTS = ("before", "during", "after")
ARRAYS = ("rgb", "segmentation", "depth")


def save_observation(path: str | Path, obs: Observation, extra: dict[str, Any] | None = None) -> None:
    """Write ``obs`` (and the JSON-serialisable ``extra``) to ``path``, atomically: a reader never
    sees half a file."""
    path = Path(path)
    arrays: dict[str, np.ndarray] = {}
    views: dict[str, dict[str, dict[str, Any]]] = {}
    for moment in MOMENTS:
        views[moment] = {}
        for camera, view in getattr(obs, moment).items():
            for name in ARRAYS:
                value = getattr(view, name)
                if value is not None:
                    arrays[f"{moment}/{camera}/{name}"] = np.asarray(value)
            views[moment][camera] = {
                "pixel_size": None if view.pixel_size is None else float(view.pixel_size),
                "robot_base": None if view.robot_base is None else [float(v) for v in view.robot_base],
            }
    meta = {"format": FORMAT, "subtask": obs.subtask.model_dump(mode="json"), "labels": list(obs.labels),
            "types": obs.types, "oracle": obs.oracle, "views": views, "extra": extra or {}}
    arrays["meta"] = np.frombuffer(json.dumps(meta, sort_keys=True).encode(), dtype=np.uint8)
    part = path.with_name(f"{path.name}.{os.getpid()}.part")
    try:
        with open(part, "wb") as f:
            np.savez_compressed(f, allow_pickle=False, **arrays)  # type: ignore[arg-type]  # stubs: kwds
        os.replace(part, path)
    finally:
        part.unlink(missing_ok=True)


def load_observation(path: str | Path) -> tuple[Observation, dict[str, Any]]:
    """The observation stored at ``path`` and the ``extra`` it was saved with; a
    :class:`~vcage.errors.DatasetError` says what is wrong with a file that is not one."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {key: archive[key] for key in archive.files}
        meta = json.loads(arrays.pop("meta").tobytes().decode())
    except (OSError, ValueError, KeyError) as exc:
        raise DatasetError(f"{path} is not a stored observation ({exc}): write it again with "
                           "save_observation") from exc
    if meta.get("format") != FORMAT:
        raise DatasetError(f"{path} holds a stored observation of format {meta.get('format')!r}; this "
                           f"vcage reads format {FORMAT}: write it again with this version")
    moments: dict[str, dict[str, View]] = {}
    for moment in MOMENTS:
        moments[moment] = {}
        for camera, info in meta["views"][moment].items():
            key = f"{moment}/{camera}/"
            base = info["robot_base"]
            moments[moment][camera] = View(rgb=arrays[key + "rgb"], segmentation=arrays[key + "segmentation"],
                                           depth=arrays.get(key + "depth"), pixel_size=info["pixel_size"],
                                           robot_base=tuple(base) if base is not None else None)
    obs = Observation(subtask=Subtask.model_validate(meta["subtask"]), labels=tuple(meta["labels"]),
                      types=dict(meta["types"]), oracle=dict(meta["oracle"]), **moments)
    return obs, dict(meta["extra"])
