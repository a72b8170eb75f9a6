"""Feature statistics as LeRobot keeps them: per-episode min/max/mean/std/count, merged exactly.

Per-episode stats live in the ``stats/<key>/<stat>`` columns of ``meta/episodes``; ``meta/stats.json``
is their merge, so appends stay correct without re-reading frames.
"""

from __future__ import annotations

from typing import Any

import numpy as np

STAT_NAMES = ("min", "max", "mean", "std", "count")
IMAGE_SAMPLE_FRAMES = 100  # frames per episode used for video stats
IMAGE_SAMPLE_SIDE = 160  # images are strided down to about this many pixels per side

Stats = dict[str, np.ndarray]


def vector_stats(values: np.ndarray) -> Stats:
    """Stats over the first axis of (T,) or (T, n) values."""
    x = np.asarray(values, dtype=np.float64).reshape(len(values), -1)
    return {"min": x.min(0), "max": x.max(0), "mean": x.mean(0), "std": x.std(0),
            "count": np.array([len(x)], dtype=np.int64)}


def image_stats(frames: np.ndarray) -> Stats:
    """Per-channel stats in [0, 1] of (T, H, W, 3) uint8 frames from a subsample; shapes (3, 1, 1).

    Computed from each channel's histogram of the 256 levels (the same values as over the pixels,
    without turning a million pixels into floats: a tenth of the time per episode)."""
    t, h, w = frames.shape[:3]
    picks = np.unique(np.linspace(0, t - 1, min(t, IMAGE_SAMPLE_FRAMES)).round().astype(np.int64))
    stride = max(1, max(h, w) // IMAGE_SAMPLE_SIDE)
    sample = np.asarray(frames[picks, ::stride, ::stride])
    if sample.dtype != np.uint8:
        raise ValueError(f"video frames must be uint8, got {sample.dtype}")
    counts = np.stack([np.bincount(sample[..., c].ravel(), minlength=256) for c in range(3)])
    counts = counts.astype(np.float64)
    levels = np.arange(256) / 255.0
    n = counts.sum(1)
    mean = counts @ levels / n
    std = np.sqrt((counts * (levels[None, :] - mean[:, None]) ** 2).sum(1) / n)
    present = counts > 0
    lo = levels[np.argmax(present, axis=1)]
    hi = levels[255 - np.argmax(present[:, ::-1], axis=1)]
    out = {name: v.reshape(3, 1, 1) for name, v in (("min", lo), ("max", hi), ("mean", mean), ("std", std))}
    out["count"] = np.array([len(picks)], dtype=np.int64)
    return out


def merge_pair(a: Stats, b: Stats) -> Stats:
    """Exact stats of the union of two samples (pooled mean and variance)."""
    na, nb = a["count"].astype(np.float64), b["count"].astype(np.float64)
    n = na + nb
    delta = b["mean"] - a["mean"]
    mean = a["mean"] + delta * (nb / n)
    var = (na * a["std"] ** 2 + nb * b["std"] ** 2) / n + delta**2 * (na * nb / n**2)
    return {"min": np.minimum(a["min"], b["min"]), "max": np.maximum(a["max"], b["max"]), "mean": mean,
            "std": np.sqrt(np.maximum(var, 0.0)), "count": a["count"] + b["count"]}


def merge(total: dict[str, Stats], episode: dict[str, Stats]) -> dict[str, Stats]:
    """``total`` with one more episode's stats merged in (new dict, inputs unchanged)."""
    return {key: merge_pair(total[key], value) if key in total else value for key, value in episode.items()}


def to_row(stats: dict[str, Stats]) -> dict[str, Any]:
    """Flat ``stats/<key>/<stat>`` columns for the episodes parquet."""
    return {f"stats/{key}/{name}": value.tolist() for key, s in stats.items() for name, value in s.items()}


def from_row(row: dict[str, Any]) -> dict[str, Stats]:
    """Inverse of :func:`to_row` on a row read back from parquet."""
    out: dict[str, Stats] = {}
    for column, value in row.items():
        if column.startswith("stats/") and value is not None:
            key, name = column[len("stats/"):].rsplit("/", 1)
            dtype = np.int64 if name == "count" else np.float64
            out.setdefault(key, {})[name] = np.asarray(value, dtype=dtype)
    return out


def to_json(stats: dict[str, Stats]) -> dict[str, dict[str, Any]]:
    """``meta/stats.json`` content: nested lists per feature and stat."""
    return {key: {name: value.tolist() for name, value in s.items()} for key, s in stats.items()}
