"""Realism perturbations of a goal image: what image models do to a scene they redraw.

A global shift and scale (the model redraws the frame slightly off), colour jitter, blur, JPEG
compression, a dropped object, and objects turned beyond the layout (a model that redraws an object
at another heading). Each is seeded; :data:`PRESETS` names the sweeps the tests and
benchmarks use.
"""

from __future__ import annotations

import io
from dataclasses import asdict, dataclass

import numpy as np
from PIL import Image, ImageFilter


@dataclass(frozen=True)
class Perturbation:
    shift: float = 0.0  # pixels, largest global shift along each image axis
    scale: float = 0.0  # largest relative global scale change
    color: float = 0.0  # largest relative per-channel gain change (and bias, x 20 levels)
    blur: float = 0.0  # Gaussian blur radius, pixels
    jpeg: int = 0  # JPEG quality (0: none)
    drop: bool = False  # leave one object out
    turn: float = 0.0  # degrees, largest extra yaw given to each object drawn

    def to_dict(self) -> dict[str, object]:
        return asdict(self)


PRESETS: dict[str, Perturbation] = {
    "none": Perturbation(),
    "shift": Perturbation(shift=12.0, scale=0.03),
    "color": Perturbation(color=0.08),
    "blur": Perturbation(blur=1.5),
    "jpeg": Perturbation(jpeg=40),
    "drop": Perturbation(drop=True),
    "turn": Perturbation(turn=60.0),
    "realistic": Perturbation(shift=8.0, scale=0.02, color=0.05, blur=0.8, jpeg=70),
}


@dataclass(frozen=True)
class Applied:
    """The global transform drawn: goal pixel = scale * (init pixel - centre) + centre + shift."""

    shift: tuple[float, float]
    scale: float


def global_transform(image: np.ndarray, p: Perturbation,
                     rng: np.random.Generator) -> tuple[np.ndarray, Applied]:
    h, w = image.shape[:2]
    dx, dy = (rng.uniform(-p.shift, p.shift, 2) if p.shift else (0.0, 0.0))
    s = 1.0 + (rng.uniform(-p.scale, p.scale) if p.scale else 0.0)
    if dx == 0 and dy == 0 and s == 1.0:
        return image, Applied((0.0, 0.0), 1.0)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    # PIL's affine maps output pixels to input pixels
    inv = (1 / s, 0, cx - (cx + dx) / s, 0, 1 / s, cy - (cy + dy) / s)
    out = Image.fromarray(image).transform((w, h), Image.Transform.AFFINE, inv, Image.Resampling.BILINEAR,
                                           fillcolor=tuple(int(c) for c in np.median(image[0], 0)))
    return np.asarray(out), Applied((float(dx), float(dy)), float(s))


def photometric(image: np.ndarray, p: Perturbation, rng: np.random.Generator) -> np.ndarray:
    out = image.astype(np.float64)
    if p.color:
        gain = 1 + rng.uniform(-p.color, p.color, 3)
        bias = rng.uniform(-20 * p.color, 20 * p.color, 3)
        out = out * gain + bias
    img = Image.fromarray(np.clip(out, 0, 255).astype(np.uint8))
    if p.blur:
        img = img.filter(ImageFilter.GaussianBlur(p.blur))
    if p.jpeg:
        buf = io.BytesIO()
        img.save(buf, format="JPEG", quality=int(p.jpeg))
        img = Image.open(io.BytesIO(buf.getvalue())).convert("RGB")
    return np.asarray(img)
