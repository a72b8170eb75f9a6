"""What the critic saw when it rejected an attempt: one small PNG per rejected attempt.

The attempt log says why an attempt was rejected; this picture shows the views the critic judged
then, so a person can check the rejection (``vcage report`` shows it). The picture is a sheet:
one row per moment the critic was shown (before the subtask, during it where a view was rendered,
after it), one column per camera, each view at half the critic's resolution. It is stored under
:data:`~vcage.data.layout.CRITIC_VIEW_PATH`, named by the attempt's sample index and attempt
number in the attempt log, and written with the attempt's log line (never before the dataset
exists). Critics that need no views (the oracle) leave none.
"""

from __future__ import annotations

import io
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PIL import Image

from vcage.data.files import atomic_write
from vcage.data.layout import CRITIC_VIEW_PATH

if TYPE_CHECKING:
    from vcage.critics.base import View

MOMENTS = ("before", "during", "after")
SCALE = 2  # every view is stored at 1/SCALE of the critic's resolution


def sheet_png(moments: Mapping[str, Mapping[str, View]]) -> bytes | None:
    """The views of ``moments`` (moment -> camera -> view) as one PNG; None if there are none."""
    rows = [[view.rgb[::SCALE, ::SCALE] for view in moments[m].values()]
            for m in MOMENTS if moments.get(m)]
    if not rows:
        return None
    width = max(len(row) for row in rows)
    h, w = rows[0][0].shape[:2]
    blank = np.zeros((h, w, 3), np.uint8)
    image = np.concatenate([np.concatenate(row + [blank] * (width - len(row)), axis=1) for row in rows])
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buffer, format="PNG", optimize=False)
    return buffer.getvalue()


def path(root: Path, sample: int, attempt: int) -> Path:
    return Path(root) / CRITIC_VIEW_PATH.format(sample=sample, attempt=attempt)


def write(root: Path, views: Mapping[tuple[int, int], bytes]) -> None:
    """Store the PNGs ``views`` ((sample, attempt) -> bytes), each atomically."""
    for (sample, attempt), png in views.items():
        atomic_write(path(root, sample, attempt), partial(Path.write_bytes, data=png))


def load(root: Path, sample: int, attempt: int) -> bytes | None:
    """The PNG of the rejected attempt ``attempt`` of sample ``sample``, or None if none was stored
    (a critic that needs no views, a stage before the critic, or a dataset made before views were
    kept)."""
    try:
        return path(root, sample, attempt).read_bytes()
    except FileNotFoundError:
        return None
