"""Images for the page, embedded as data URIs: frames as PNG, clips as animated WebP, charts as SVG.

Everything the report shows travels inside the one HTML file, so it opens anywhere, offline.
"""

from __future__ import annotations

import base64
import io
from collections.abc import Sequence

import numpy as np
from PIL import Image

CLIP_FPS = 10  # clips are shown at most this many frames per second (real time)
CLIP_FRAMES = 150  # ... and hold at most this many frames (longer episodes are sampled sparser)
CLIP_QUALITY = 70


def data_uri(data: bytes, mime: str) -> str:
    return f"data:{mime};base64,{base64.b64encode(data).decode('ascii')}"


def png_uri(image: np.ndarray) -> str:
    """An RGB image (H, W, 3) uint8 as a PNG data URI."""
    buffer = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(buffer, format="PNG")
    return data_uri(buffer.getvalue(), "image/png")


def svg_uri(svg: str) -> str:
    return data_uri(svg.encode("utf-8"), "image/svg+xml")


def side_by_side(images: Sequence[np.ndarray], gap: int = 2) -> np.ndarray:
    """Images of one height next to each other, with a white gap between them."""
    height = max(image.shape[0] for image in images)
    parts: list[np.ndarray] = []
    for image in images:
        if parts:
            parts.append(np.full((height, gap, 3), 255, np.uint8))
        pad = height - image.shape[0]
        parts.append(np.pad(image, ((0, pad), (0, 0), (0, 0)), constant_values=255) if pad else image)
    return np.concatenate(parts, axis=1)


def clip_frames(length: int, fps: int) -> list[int]:
    """The frames a clip of a ``length``-frame episode recorded at ``fps`` shows."""
    step = max(1, round(fps / CLIP_FPS), -(-length // CLIP_FRAMES))
    return list(range(0, length, step))


def clip_uri(videos: Sequence[np.ndarray], fps: int) -> tuple[str, float]:
    """An animated WebP of ``videos`` (each (T, H, W, 3), shown side by side) in real time, looping;
    returns the data URI and the clip's frames per second."""
    length = min(len(v) for v in videos)
    frames = clip_frames(length, fps)
    step = frames[1] - frames[0] if len(frames) > 1 else 1
    images = [Image.fromarray(side_by_side([v[i] for v in videos])) for i in frames]
    buffer = io.BytesIO()
    images[0].save(buffer, format="WEBP", save_all=True, append_images=images[1:],
                   duration=round(1000 * step / fps), loop=0, quality=CLIP_QUALITY, method=4)
    return data_uri(buffer.getvalue(), "image/webp"), fps / step
