"""Checkpoint files: written atomically, found in a run directory, read back with clear errors.

A run directory ``OUT`` holds ``OUT/checkpoints/step-<step>.pt``, one per checkpoint interval and
one at the end (or only the newest few, when the run keeps that many: each is about 20 MB at the
default sizes). Each is a ``torch.save`` of plain data and tensors (read back with
``weights_only=True``: loading a checkpoint runs no code) written to a temporary name in the same
directory, flushed to disk, and moved into place with ``os.replace``: a crash leaves either the
previous checkpoints or the new one, never a torn file.
"""

from __future__ import annotations

import contextlib
import os
import re
from pathlib import Path
from typing import Any

import torch

from vcage.policy.errors import CheckpointError

FORMAT, FORMAT_VERSION = "vcage-policy", 1
CHECKPOINTS = "checkpoints"
NAME = re.compile(r"^step-(\d+)\.pt$")
REQUIRED = ("config", "dataset", "obs_features", "action_feature", "normalization", "step", "model", "ema")
# What only resuming reads: an exported checkpoint (export_for_evaluation) leaves these out.
RESUME_STATE = ("model", "optimizer", "rng", "sampler")
EVALUATION_ONLY = "evaluation_only"


def checkpoint_path(out: Path, step: int) -> Path:
    return Path(out) / CHECKPOINTS / f"step-{step:08d}.pt"


def checkpoints(out: Path) -> list[Path]:
    """The checkpoint files of a run directory, oldest step first."""
    folder = Path(out) / CHECKPOINTS
    if not folder.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in folder.iterdir() if (m := NAME.match(p.name)) and p.is_file()]
    return [p for _, p in sorted(found)]


def prune_checkpoints(out: Path, keep: int) -> list[Path]:
    """Delete all but the ``keep`` newest checkpoints of a run directory; the deleted paths."""
    if keep < 1:
        raise CheckpointError(f"a run keeps at least its latest checkpoint, got keep={keep}")
    found = checkpoints(out)
    old = found[:-keep]
    for path in old:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
    return old


def latest_checkpoint(out: Path) -> Path | None:
    found = checkpoints(out)
    return found[-1] if found else None


def resolve(path: str | Path) -> Path:
    """A checkpoint file, or the latest checkpoint of a run directory."""
    path = Path(path)
    if path.is_dir():
        latest = latest_checkpoint(path)
        if latest is None:
            raise CheckpointError(f"{path} holds no checkpoint ({CHECKPOINTS}/step-*.pt); train one with "
                                  f"`vcage train DATASET --out {path}`")
        return latest
    if not path.is_file():
        raise CheckpointError(f"no checkpoint at {path}; give a checkpoint file or the --out directory of "
                              "`vcage train`")
    return path


def save_checkpoint(path: Path, payload: dict[str, Any]) -> None:
    """Write ``payload`` to ``path`` atomically (temporary file, fsync, ``os.replace``)."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as f:
            torch.save({"format": FORMAT, "format_version": FORMAT_VERSION, **payload}, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError):
            raise CheckpointError(f"cannot write the checkpoint {path}: {exc.strerror or exc}; choose "
                                  "another --out (the checkpoints written before are kept)") from None
        raise
    with contextlib.suppress(OSError):  # make the rename itself durable
        fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Read a checkpoint file (or a run directory's latest); CheckpointError if it is missing,
    unreadable, or not a vcage policy checkpoint of a format this vcage reads."""
    path = resolve(path)
    try:
        payload = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # torch raises RuntimeError, UnpicklingError, EOFError, zip errors ...
        raise CheckpointError(f"{path} is not a readable checkpoint ({type(exc).__name__}: "
                              f"{str(exc).splitlines()[0][:200] if str(exc) else 'no detail'}); it is "
                              "damaged: delete it to resume from the one before, or train again") from None
    if not isinstance(payload, dict) or payload.get("format") != FORMAT:
        raise CheckpointError(f"{path} is not a vcage policy checkpoint (written by `vcage train`)")
    if payload.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(f"{path} has checkpoint format {payload.get('format_version')!r}; this vcage "
                              f"reads format {FORMAT_VERSION}: evaluate it with the vcage that wrote it "
                              f"({payload.get('vcage_version', 'unknown')}) or train again")
    required = [k for k in REQUIRED if not (payload.get(EVALUATION_ONLY) and k in RESUME_STATE)]
    missing = [k for k in required if k not in payload]
    if missing:
        raise CheckpointError(f"{path} lacks {', '.join(missing)}; it is damaged: train again")
    if isinstance(payload["config"], dict) and "rotations" not in payload["config"]:
        # written before policies chose how to read quaternions: they read them as stored
        payload["config"] = {**payload["config"], "rotations": "quaternion"}
    payload["path"] = str(path)
    return payload


def export_for_evaluation(source: str | Path, destination: str | Path, **extra: Any) -> Path:
    """Copy a checkpoint with what evaluation reads (configuration, dataset record, normalisation,
    EMA weights, loss history) and without what only resuming reads (the raw weights, the
    optimiser, the generators and the sampler): about a quarter of the size, for moving a policy
    trained elsewhere (a GPU machine) to where it is evaluated. ``extra`` entries (plain data, such
    as the training run's timings) are stored beside. The copy cannot resume training."""
    payload = load_checkpoint(source)
    kept = {k: v for k, v in payload.items()
            if k not in RESUME_STATE and k not in ("format", "format_version", "path")}
    destination = Path(destination)
    save_checkpoint(destination, {**kept, **extra, EVALUATION_ONLY: True})
    return destination
