"""MP4 encoding and decoding of RGB frame stacks with PyAV (yuv420p, one frame per 1/fps)."""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path

import av
import numpy as np

from vcage.errors import DatasetError

PIX_FMT = "yuv420p"

# Encoder preference and fast settings; g=2 keeps frames close to the source and makes seeking
# cheap, as LeRobot does. H.264 comes first: SVT-AV1 (LeRobot's default) was seen to deadlock in
# its thread pool during a long generation run on a 2-core machine, so it is only a fallback,
# restricted to one thread. Small videos need no more than one encoder thread anyway.
ENCODER_OPTIONS: dict[str, dict[str, str]] = {
    "libx264": {"preset": "veryfast", "crf": "20", "g": "2", "threads": "1"},
    "h264": {"preset": "veryfast", "crf": "20", "g": "2", "threads": "1"},
    "libsvtav1": {"preset": "11", "crf": "30", "g": "2", "svtav1-params": "lp=1"},
    "libaom-av1": {"cpu-used": "8", "crf": "30", "g": "2", "threads": "1"},
    "mpeg4": {"qmin": "2", "qmax": "4", "g": "2", "threads": "1"},
}


def available_encoders() -> list[str]:
    """The preferred encoders this PyAV wheel can actually open for writing, best first."""
    found = []
    for name in ENCODER_OPTIONS:
        if name not in av.codecs_available:
            continue
        try:
            av.Codec(name, "w")
        except Exception:  # noqa: BLE001 - a listed codec without an encoder
            continue
        found.append(name)
    return found


def choose_encoder() -> str:
    """The best available encoder; raises DatasetError when the wheel ships none of them."""
    found = available_encoders()
    if not found:
        raise DatasetError(
            f"no usable video encoder in this PyAV build (wanted one of {', '.join(ENCODER_OPTIONS)}); "
            "install an `av` wheel that bundles libsvtav1 or libx264"
        )
    return found[0]


def codec_name(encoder: str) -> str:
    """The format name of an encoder's output (``libsvtav1`` -> ``av1``), as LeRobot records it."""
    return str(av.Codec(encoder, "w").canonical_name)


def check_frame_size(height: int, width: int, key: str = "video") -> None:
    """yuv420p needs even, positive sizes; raise DatasetError otherwise."""
    if height <= 0 or width <= 0 or height % 2 or width % 2:
        raise DatasetError(
            f"{key}: frame size {height}x{width} is not usable for {PIX_FMT} video; "
            "height and width must be positive and even"
        )


def encode_video(path: Path, frames: np.ndarray, fps: int, encoder: str) -> None:
    """Write ``frames`` (T,H,W,3 uint8) to ``path`` as MP4; frame i has timestamp i/fps."""
    if frames.ndim != 4 or frames.shape[-1] != 3 or frames.dtype != np.uint8 or len(frames) == 0:
        raise DatasetError(f"video frames must be (T,H,W,3) uint8 with T >= 1, got {frames.dtype} "
                           f"{frames.shape}")
    check_frame_size(frames.shape[1], frames.shape[2])
    os.environ.setdefault("SVT_LOG", "1")  # SVT-AV1 prints ~20 info/warn lines per video; errors only
    time_base = Fraction(1, fps)
    with av.open(str(path), "w", format="mp4") as container:
        stream = container.add_stream(encoder, rate=fps, options=dict(ENCODER_OPTIONS.get(encoder, {})))
        assert isinstance(stream, av.VideoStream)
        stream.width = int(frames.shape[2])
        stream.height = int(frames.shape[1])
        stream.pix_fmt = PIX_FMT
        stream.codec_context.time_base = time_base
        for i, rgb in enumerate(frames):
            frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(rgb), format="rgb24")
            frame.pts = i
            frame.time_base = time_base
            container.mux(stream.encode(frame))
        container.mux(stream.encode(None))


def decode_video(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Decode an MP4 to (frames (T,H,W,3) uint8, timestamps (T,) float64 seconds)."""
    frames: list[np.ndarray] = []
    times: list[float] = []
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            for frame in container.decode(stream):
                frames.append(frame.to_ndarray(format="rgb24"))
                times.append(float(frame.time) if frame.time is not None else float("nan"))
    except (av.FFmpegError, IndexError, OSError) as exc:
        raise DatasetError(f"cannot decode video {path}: {exc}") from exc
    if not frames:
        raise DatasetError(f"video {path} holds no frames")
    return np.stack(frames), np.asarray(times, dtype=np.float64)
