"""The image-editing interface ``M(I_init, D_scene) -> I_goal`` every backend implements.

An editor gets the initial top-down view (``TopView``: RGB, segmentation, camera, poses) with the
empty table and the description, and returns the goal image. An offline editor may also return the
ground-truth poses it drew (``truth``), so matching can be scored; model backends return none.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from vcage.registry import Registry
from vcage.synthesis.description import SceneDescription
from vcage.synthesis.errors import ImageEditError
from vcage.synthesis.views import TopView


@dataclass(frozen=True)
class EditResult:
    image: np.ndarray  # (H, W, 3) uint8, the size of I_init
    truth: dict[str, tuple[float, float, float]] | None = None  # drawn poses (x, y, yaw), if known
    dropped: tuple[str, ...] = ()  # objects the editor left out on purpose (ground truth)
    info: dict[str, object] = field(default_factory=dict)


class ImageEditor(ABC):
    name = "base"

    @abstractmethod
    def edit(self, init: TopView, empty: np.ndarray, desc: SceneDescription,
             rng: np.random.Generator) -> EditResult:
        """The goal image for ``desc``; raises :class:`ImageEditError` when none can be had."""


def check_goal_image(image: object, init: TopView) -> np.ndarray:
    """``image`` as (H, W, 3) uint8 of ``init``'s size, or :class:`ImageEditError` saying what is wrong."""
    arr = np.asarray(image)
    if arr.ndim == 3 and arr.shape[2] == 4:
        arr = arr[..., :3]
    if arr.ndim != 3 or arr.shape[2] != 3:
        raise ImageEditError(f"the goal image has shape {arr.shape}, not an RGB image")
    if arr.shape[:2] != init.rgb.shape[:2]:
        raise ImageEditError(f"the goal image is {arr.shape[1]}x{arr.shape[0]}, not the initial image's "
                             f"{init.rgb.shape[1]}x{init.rgb.shape[0]}: the model must keep the size")
    if arr.dtype != np.uint8:
        raise ImageEditError(f"the goal image has pixel type {arr.dtype}, not uint8")
    if float(arr.std()) < 2.0:
        raise ImageEditError("the goal image is blank (a single colour)")
    return arr


EDITORS: Registry[type[ImageEditor]] = Registry("image editor", error=ImageEditError)
