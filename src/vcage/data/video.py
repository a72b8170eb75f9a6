"""MP4 encoding and decoding of RGB frame stacks with PyAV (yuv420p, one frame per 1/fps).

PyAV is imported by the functions that use it, not with this module: reading a dataset's tables
(what a state-based policy trains on) works where the codec library is not installed.
"""

from __future__ import annotations

import os
import struct
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import numpy as np

from vcage.errors import CorruptDatasetError, DatasetError

PIX_FMT = "yuv420p"

# Encoder preference and fast settings; g=2 keeps frames close to the source and makes seeking
# cheap, as LeRobot does. H.264 comes first: SVT-AV1 (LeRobot's default) was seen to deadlock in
# its thread pool during a long generation run on a 2-core machine, so it is only a fallback,
# restricted to one thread. Small videos need no more than one encoder thread anyway. No B-frames
# (``bf=0``): every packet is shown when it is decoded, so episodes encoded one at a time can be
# joined into one file by copying their packets (:func:`concat_videos`) with increasing timestamps.
ENCODER_OPTIONS: dict[str, dict[str, str]] = {
    "libx264": {"preset": "veryfast", "crf": "20", "g": "2", "bf": "0", "threads": "1"},
    "h264": {"preset": "veryfast", "crf": "20", "g": "2", "bf": "0", "threads": "1"},
    "libsvtav1": {"preset": "11", "crf": "30", "g": "2", "svtav1-params": "lp=1"},
    "libaom-av1": {"cpu-used": "8", "crf": "30", "g": "2", "threads": "1"},
    "mpeg4": {"qmin": "2", "qmax": "4", "g": "2", "bf": "0", "threads": "1"},
}


def _read_errors() -> tuple[type[BaseException], ...]:
    """What reading a damaged file raises: PyAV's errors, and an AttributeError where a damaged
    container gives its stream no codec context (found by the corruption fuzz test)."""
    import av
    return (av.FFmpegError, IndexError, OSError, ValueError, AttributeError)


def available_encoders() -> list[str]:
    """The preferred encoders this PyAV wheel can actually open for writing, best first."""
    import av
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
    import av
    return str(av.Codec(encoder, "w").canonical_name)


def encoder_for(codecs: set[str]) -> str:
    """An available encoder whose output is one of ``codecs`` (a dataset's recorded codec);
    DatasetError where this PyAV build has none."""
    for encoder in available_encoders():
        if codec_name(encoder) in codecs:
            return encoder
    raise DatasetError(f"the dataset uses video codec {sorted(codecs)} but this PyAV build cannot encode it; "
                       "use the environment that created the dataset")


def check_frame_size(height: int, width: int, key: str = "video") -> None:
    """yuv420p needs even, positive sizes; raise DatasetError otherwise."""
    if height <= 0 or width <= 0 or height % 2 or width % 2:
        raise DatasetError(
            f"{key}: frame size {height}x{width} is not usable for {PIX_FMT} video; "
            "height and width must be positive and even"
        )


def encode_video(path: Path, frames: np.ndarray, fps: int, encoder: str) -> None:
    """Write ``frames`` (T,H,W,3 uint8) to ``path`` as MP4; frame i has timestamp i/fps."""
    import av
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
    import av
    frames: list[np.ndarray] = []
    times: list[float] = []
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            for frame in container.decode(stream):
                frames.append(frame.to_ndarray(format="rgb24"))
                times.append(float(frame.time) if frame.time is not None else float("nan"))
    except _read_errors() as exc:
        raise CorruptDatasetError(f"cannot decode video {path}: {exc}") from exc
    if not frames:
        raise CorruptDatasetError(f"video {path} holds no frames")
    return np.stack(frames), np.asarray(times, dtype=np.float64)


@dataclass(frozen=True)
class Probe:
    """What a video's container says without decoding: frame count and frame size."""

    frames: int
    height: int
    width: int


def check_boxes(path: Path) -> None:
    """Raise CorruptDatasetError unless the MP4's top-level boxes tile the file exactly.

    A truncated MP4 ends inside a box (its ``moov`` or ``mdat``); reading the box headers costs a
    few small reads, however long the video.
    """
    size = path.stat().st_size
    offset = 0
    with path.open("rb") as f:
        while offset < size:
            f.seek(offset)
            head = f.read(16)
            if len(head) < 8:
                raise CorruptDatasetError(f"{path} ends inside a box header at byte {offset}; the file is "
                                          "truncated")
            box, kind = struct.unpack(">I", head[:4])[0], head[4:8]
            if box == 1:
                if len(head) < 16:
                    raise CorruptDatasetError(f"{path} ends inside a box header at byte {offset}; the file "
                                              "is truncated")
                box = struct.unpack(">Q", head[8:16])[0]
            elif box == 0:  # the last box runs to the end of the file
                box = size - offset
            if box < 8:
                raise CorruptDatasetError(f"{path} has a malformed box {kind!r} at byte {offset}")
            if offset + box > size:
                raise CorruptDatasetError(
                    f"{path} is truncated: box {kind.decode('latin-1')!r} at byte {offset} needs "
                    f"{box} bytes, the file has {size - offset} left")
            offset += box
    if size == 0:
        raise CorruptDatasetError(f"{path} is empty")


def probe_video(path: Path) -> Probe:
    """Frame count and size from the container (no decoding); CorruptDatasetError if it cannot be read.

    The count is the stream's ``nb_frames`` from the MP4 index; where the container does not record
    it, the packets are counted (read, not decoded).
    """
    import av
    check_boxes(path)
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            frames = int(stream.frames)
            if frames <= 0:
                frames = sum(1 for packet in container.demux(stream) if packet.size)
            return Probe(frames, int(stream.codec_context.height), int(stream.codec_context.width))
    except _read_errors() as exc:
        raise CorruptDatasetError(f"cannot open video {path}: {exc}") from exc


def decode_times(path: Path) -> np.ndarray:
    """Decode every frame of an MP4 (without converting it to RGB) and return the timestamps (T,).

    Costs a full decode; CorruptDatasetError if the stream cannot be decoded.
    """
    import av
    times: list[float] = []
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            for frame in container.decode(stream):
                times.append(float(frame.time) if frame.time is not None else float("nan"))
    except _read_errors() as exc:
        raise CorruptDatasetError(f"cannot decode video {path}: {exc}") from exc
    return np.asarray(times, dtype=np.float64)


def packet_digests(path: Path, windows: list[tuple[float, float]], fps: int) -> list[str]:
    """A SHA-256 of the encoded bytes of the packets whose timestamps fall in each ``(start, stop)``
    window (seconds, as an episode's row gives them), read in one pass without decoding.

    :func:`concat_videos` copies packets unchanged, so an episode's digest taken from the file it
    was encoded to holds in every file it is joined into. CorruptDatasetError if the file cannot
    be read.
    """
    import hashlib

    import av
    half = 0.5 / fps
    digests = [hashlib.sha256() for _ in windows]
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            tb = stream.time_base
            assert tb is not None
            for packet in container.demux(stream):
                if packet.pts is None or not packet.size:
                    continue
                t = float(packet.pts * tb)
                for (start, stop), digest in zip(windows, digests, strict=True):
                    if start - half <= t < stop - half:
                        digest.update(bytes(packet))
    except _read_errors() as exc:
        raise CorruptDatasetError(f"cannot read video {path}: {exc}") from exc
    return [d.hexdigest() for d in digests]


def concat_videos(sources: list[tuple[Path, int, int]], out: Path, fps: int) -> None:
    """Write the frames ``first .. first + n - 1`` of each ``(path, first, n)`` source, one after the
    other, to ``out``.

    Stream copy (no re-encoding, so decoded frames stay bit-identical and every packet's bytes, and
    so its content digest, are kept): packets are copied with their timestamps shifted, so that
    source k's frame ``first + i`` gets timestamp ``(frames of the sources before k + i) / fps``.
    Each clip must start with a key frame and its frames must not reference frames outside it
    (true of the episodes vcage encodes one at a time); the sources must share codec, size and
    time base. CorruptDatasetError names a source that cannot be read or has fewer frames than
    asked; DatasetError one that does not match, or a clip that does not start at a key frame.
    """
    import av
    frame_seconds = Fraction(1, fps)
    with av.open(str(out), "w", format="mp4") as container:
        target: av.VideoStream | None = None
        template: tuple[object, ...] | None = None
        offset = Fraction(0)  # seconds before the current source
        for path, first, keep in sources:
            copied = 0
            try:
                with av.open(str(path)) as source:
                    stream = source.streams.video[0]
                    ctx = stream.codec_context
                    shape = (ctx.name, ctx.width, ctx.height, stream.time_base, bytes(ctx.extradata or b""))
                    if target is None:
                        target, template = container.add_stream_from_template(stream), shape
                    elif shape != template:
                        raise DatasetError(f"cannot join {path} to the videos before it: codec, size, time "
                                           "base or encoder settings differ")
                    tb = stream.time_base
                    assert tb is not None
                    begin = Fraction(first) * frame_seconds
                    shift = int((offset - begin) / tb)
                    low = begin - frame_seconds / 2  # the clip's frames lie in [low, high)
                    high = begin + Fraction(keep) * frame_seconds - frame_seconds / 2
                    for packet in source.demux(stream):
                        if packet.dts is None or packet.pts is None:
                            continue  # the demuxer's empty flush packet
                        if not low <= packet.pts * tb < high:
                            continue
                        if not copied and not packet.is_keyframe:
                            raise DatasetError(f"frame {first} of {path} is not a key frame; a clip cannot "
                                               "start there without re-encoding")
                        packet.pts += shift
                        packet.dts += shift
                        packet.stream = target
                        container.mux(packet)
                        copied += 1
            except _read_errors() as exc:
                raise CorruptDatasetError(f"cannot read video {path}: {exc}") from exc
            if copied != keep:
                raise CorruptDatasetError(f"video {path} holds {copied} of the {keep} frames to copy")
            offset += Fraction(keep) * frame_seconds


def decode_window(path: Path, start: float, stop: float, fps: int) -> np.ndarray:
    """Decode the frames of an MP4 with timestamps in ``[start, stop)`` (half a frame of tolerance),
    seeking to the key frame before ``start`` rather than decoding the file from its beginning."""
    import av
    half = 0.5 / fps
    frames: list[np.ndarray] = []
    try:
        with av.open(str(path)) as container:
            stream = container.streams.video[0]
            tb = stream.time_base
            if start > half and tb is not None:
                container.seek(int((start - half) / tb), stream=stream, backward=True, any_frame=False)
            for frame in container.decode(stream):
                time = float(frame.time) if frame.time is not None else float("nan")
                if time >= stop - half:
                    break
                if time >= start - half:
                    frames.append(frame.to_ndarray(format="rgb24"))
    except _read_errors() as exc:
        raise CorruptDatasetError(f"cannot decode video {path}: {exc}") from exc
    if not frames:
        raise CorruptDatasetError(f"video {path} holds no frames between {start:.3f} s and {stop:.3f} s")
    return np.stack(frames)
