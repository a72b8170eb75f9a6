"""Training a policy on a dataset: deterministic on the CPU, checkpointed, resumable.

Everything random comes from the run's seed: the weights' initialisation (torch's global
generator, seeded), the diffusion noise and steps (a generator the run owns), and the batches
(:class:`BatchSampler`). A checkpoint holds the weights, their EMA, the optimiser, both generators'
states and the sampler's position, so resuming from it continues exactly where the run was: on the
CPU with the same number of threads, a resumed run ends with the same weights as an uninterrupted one.
"""

from __future__ import annotations

import contextlib
import math
import os
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
import torch

from vcage import __version__
from vcage.errors import ConfigError
from vcage.policy.checkpoint import (
    EVALUATION_ONLY,
    checkpoint_path,
    latest_checkpoint,
    load_checkpoint,
    prune_checkpoints,
    save_checkpoint,
)
from vcage.policy.config import TrainConfig
from vcage.policy.dataset import TrainingData, load_training_data
from vcage.policy.devices import torch_device
from vcage.policy.ema import Ema
from vcage.policy.encoding import VectorEncoder
from vcage.policy.errors import CheckpointError, PolicyError, TrainingDivergedError
from vcage.policy.graphed import GraphedStep
from vcage.policy.models import Policy, make_policy
from vcage.policy.normalize import Normalizer
from vcage.policy.sampler import BatchSampler
from vcage.policy.windows import make_windows

Progress = Callable[[int, int, float], None]  # (step done, steps in all, loss of that step)
LOSS_WINDOW = 50  # the final loss reported is the mean of this many last steps


@dataclass(frozen=True)
class TrainSummary:
    checkpoint: Path
    config: TrainConfig
    start_step: int  # the step this invocation started from (0, or the resumed checkpoint's)
    steps: int  # the step the run reached
    final_loss: float  # mean loss of the last LOSS_WINDOW steps
    seconds: float  # wall time of this invocation's training steps
    samples_per_second: float
    parameters: int
    notes: tuple[str, ...]


@contextlib.contextmanager
def deterministic(threads: int | None, device: torch.device | None = None) -> Iterator[None]:
    """Deterministic kernels (and ``threads`` intra-op threads, if given) for the duration.

    On a GPU, cuBLAS is given the fixed workspace its deterministic mode needs, and a kernel with no
    deterministic version warns instead of stopping the run: results are reproducible on the CPU
    (what the tests check), and on a GPU as far as its kernels allow."""
    was, old_threads = torch.are_deterministic_algorithms_enabled(), torch.get_num_threads()
    on_gpu = device is not None and device.type == "cuda"
    if on_gpu:
        os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")
    torch.use_deterministic_algorithms(True, warn_only=on_gpu)
    if threads is not None:
        torch.set_num_threads(threads)
    try:
        yield
    finally:
        torch.use_deterministic_algorithms(was)
        torch.set_num_threads(old_threads)


def learning_rate(config: TrainConfig, step: int) -> float:
    """Linear warm-up, then cosine decay to zero at ``config.steps``."""
    if step < config.warmup_steps:
        return config.lr * (step + 1) / config.warmup_steps
    progress = (step - config.warmup_steps) / max(1, config.steps - config.warmup_steps)
    return config.lr * 0.5 * (1 + math.cos(math.pi * min(1.0, progress)))


def stored_config(out: str | Path) -> TrainConfig | None:
    """The configuration of the run in ``out`` (its latest checkpoint), or None if it has none."""
    latest = latest_checkpoint(Path(out))
    return None if latest is None else TrainConfig.from_dict(load_checkpoint(latest)["config"])


class Run:
    """The state of one training run: data tensors, model, EMA, optimiser, generators, sampler."""

    def __init__(self, data: TrainingData, config: TrainConfig, normalization: dict[str, Normalizer],
                 device: torch.device, graph: bool = False) -> None:
        self.data, self.config, self.normalization, self.device = data, config, normalization, device
        windows = make_windows(data.lengths, config.n_obs_steps, config.horizon, config.obs_stride)
        self.obs_index = torch.from_numpy(windows.obs)
        self.action_index = torch.from_numpy(windows.action)
        self.obs = torch.from_numpy(normalization["obs"].normalize(data.obs)).to(device)
        self.action = torch.from_numpy(normalization["action"].normalize(data.action)).to(device)
        # each window's subtask is its current (last observed) frame's
        self.subtask = None if data.subtask is None else torch.from_numpy(data.subtask).to(device)
        torch.manual_seed(config.seed)
        self.model: Policy = make_policy(config, data.obs.shape[1], data.action.shape[1],
                                         data.subtasks).to(device)
        self.ema = Ema(self.model, config.ema_power, config.ema_max_decay)
        self.optimizer = torch.optim.AdamW(self.model.parameters(), lr=config.lr,
                                           weight_decay=config.weight_decay, capturable=graph)
        self.generator = torch.Generator().manual_seed(config.seed)
        self.sampler = BatchSampler(len(windows), config.batch_size, config.seed)
        self.step = 0
        self.losses: list[float] = []
        self.graphed = GraphedStep(self) if graph else None  # captured at its first steps, after restore

    def batch(self) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]:
        """The next batch's observation windows, action chunks and (if conditioned) subtasks."""
        rows = torch.from_numpy(self.sampler.next_batch())
        return self.gather(rows, self.obs_index, self.action_index)

    def gather(self, rows: torch.Tensor, obs_index: torch.Tensor,
               action_index: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]:
        """The windows of ``rows``: observations, actions and the subtask of each one's current frame."""
        frames = obs_index[rows]
        subtask = None if self.subtask is None else self.subtask[frames[:, -1]]
        return self.obs[frames], self.action[action_index[rows]], subtask

    def train_step(self) -> float:
        """One optimiser step; TrainingDivergedError (before any weight changes, except in a CUDA
        graph, where it comes after the step) on a non-finite loss or gradient norm."""
        if self.graphed is not None:
            lr, rows = learning_rate(self.config, self.step), self.sampler.next_batch()
            draws = self.model.draws(self.graphed.shape, self.generator, torch.device("cpu"))
            value, grad_norm = self.graphed.step(rows, draws, lr, self.ema.decay())
            for what, number in (("loss", value), ("gradient norm", grad_norm)):
                if not math.isfinite(number):
                    raise TrainingDivergedError(f"the {what} became {number} at step {self.step + 1}")
            self.step += 1
            self.losses.append(value)
            return value
        for group in self.optimizer.param_groups:
            group["lr"] = learning_rate(self.config, self.step)
        obs, action, subtask = self.batch()
        loss = self.model.loss(obs, action, self.generator, subtask)
        value = float(loss.item())
        if not math.isfinite(value):
            raise TrainingDivergedError(f"the loss became {value} at step {self.step + 1}")
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        norm = torch.nn.utils.clip_grad_norm_(self.model.parameters(), self.config.grad_clip)
        if not math.isfinite(float(norm)):
            raise TrainingDivergedError(f"the gradient norm became {float(norm)} at step {self.step + 1}")
        self.optimizer.step()
        self.ema.update(self.model)
        self.step += 1
        self.losses.append(value)
        return value

    def payload(self) -> dict[str, Any]:
        return {
            "vcage_version": __version__, "torch_version": str(torch.__version__),
            "config": self.config.to_dict(), "dataset": self.data.info.to_dict(),
            "obs_features": [f.to_dict() for f in self.data.obs_features],
            "action_feature": self.data.action_feature.to_dict(), "subtasks": self.data.subtasks,
            "normalization": {k: v.to_dict() for k, v in self.normalization.items()},
            "step": self.step, "loss_history": torch.tensor(self.losses, dtype=torch.float64),
            "model": self.model.state_dict(), "ema": self.ema.state_dict(),
            "optimizer": _plain_lr(self.optimizer.state_dict()),
            "rng": {"generator": self.generator.get_state(), "torch": torch.get_rng_state()},
            "sampler": self.sampler.state_dict(),
        }

    def restore(self, payload: dict[str, Any]) -> None:
        self.model.load_state_dict(payload["model"])
        self.ema.load_state_dict(payload["ema"])
        self.optimizer.load_state_dict(payload["optimizer"])
        self.generator.set_state(payload["rng"]["generator"])
        torch.set_rng_state(payload["rng"]["torch"])
        self.sampler.load_state_dict(payload["sampler"])
        self.step = int(payload["step"])
        self.losses = [float(v) for v in payload["loss_history"].tolist()]


def _plain_lr(state: dict[str, Any]) -> dict[str, Any]:
    """An optimiser state whose learning rates are numbers (a CUDA graph keeps each in a tensor)."""
    groups = [{**g, "lr": float(g["lr"])} for g in state["param_groups"]]
    return {**state, "param_groups": groups}


def config_differences(stored: TrainConfig, given: TrainConfig) -> list[str]:
    """The fields (other than ``steps``) in which ``given`` differs from ``stored``."""
    return [f"{f.name}: {getattr(stored, f.name)!r} in the run, {getattr(given, f.name)!r} given"
            for f in fields(TrainConfig)
            if f.name != "steps" and getattr(stored, f.name) != getattr(given, f.name)]


def _resume_from(out: Path, config: TrainConfig, resume: bool) -> dict[str, Any] | None:
    if out.exists() and not out.is_dir():
        raise PolicyError(f"{out} is a file; choose a directory for --out")
    latest = latest_checkpoint(out)
    if latest is None:
        return None
    if not resume:
        raise PolicyError(f"{out} already holds a training run (last checkpoint {latest.name}); pass "
                          "--resume to continue it, or choose another --out")
    payload = load_checkpoint(latest)
    if payload.get(EVALUATION_ONLY):
        raise CheckpointError(f"{latest} was exported for evaluation (it has no optimiser state) and cannot "
                              f"resume training; train again into another --out")
    diffs = config_differences(TrainConfig.from_dict(payload["config"]), config)
    if diffs:
        raise ConfigError(f"--resume continues the run in {out} with its own configuration, which differs: "
                          f"{'; '.join(diffs)}; leave those options out (only --steps may change)")
    if int(payload["step"]) > config.steps:
        raise ConfigError(f"the run in {out} is at step {payload['step']}, past --steps {config.steps}")
    return payload


def floors(encoder: VectorEncoder, config: TrainConfig) -> np.ndarray:
    """The smallest normalisation scale of each value ``encoder`` gives the policy (its observation
    input or its action): ``rotation_floor`` for rotation-matrix columns, ``norm_floor`` for the rest
    (see :mod:`vcage.policy.normalize`)."""
    mask = encoder.rotation_mask()
    return np.where(mask, config.rotation_floor, config.norm_floor)


def train(dataset: str | Path, out: str | Path, config: TrainConfig, *, resume: bool = False,
          device: str = "cpu", threads: int | None = None, progress: Progress | None = None,
          keep: int | None = None, graph: bool = False) -> TrainSummary:
    """Train ``config.policy`` on ``dataset``, writing checkpoints to ``out/checkpoints/`` (only the
    ``keep`` newest stay, if given: a new one is written before older ones are deleted).
    ``graph`` captures the step as a CUDA graph (:mod:`vcage.policy.graphed`; CUDA devices only).

    With ``resume``, continue from the latest checkpoint in ``out`` (a fresh start if there is
    none). A non-finite loss stops the run with :class:`TrainingDivergedError`; the checkpoints
    written before stay as they were.
    """
    out, where = Path(out), torch_device(device)
    if keep is not None and (isinstance(keep, bool) or not isinstance(keep, int) or keep < 1):
        raise ConfigError(f"--keep-checkpoints must be a positive integer, got {keep!r}")
    saved = _resume_from(out, config, resume)
    data = load_training_data(dataset, config)
    if saved is not None and saved["dataset"]["fingerprint"] != data.info.fingerprint:
        raise CheckpointError(f"the run in {out} was trained on another dataset ({saved['dataset']['path']}, "
                              f"fingerprint {saved['dataset']['fingerprint']}) than {dataset} (fingerprint "
                              f"{data.info.fingerprint}); resume with that dataset or choose another --out")
    if saved is not None:
        normalization = {k: Normalizer.from_dict(v) for k, v in saved["normalization"].items()}
    else:
        normalization = {
            "obs": Normalizer.fit(data.obs, config.obs_norm, floors(VectorEncoder(
                data.obs_features, config.rotations, config.relative_objects), config)),
            "action": Normalizer.fit(data.action, "min_max", floors(VectorEncoder(
                [data.action_feature], config.rotations), config))}
    with deterministic(threads, where):
        if graph and where.type != "cuda":
            raise ConfigError(f"a CUDA graph of the training step needs a CUDA device, not {device!r}")
        run = Run(data, config, normalization, where, graph)
        if saved is not None:
            run.restore(saved)
        start, last_saved = run.step, (checkpoint_path(out, run.step) if saved is not None else None)
        began = time.perf_counter()
        while run.step < config.steps:
            try:
                loss = run.train_step()
            except TrainingDivergedError as exc:
                kept = (f"the last good checkpoint is {last_saved}" if last_saved
                        else "no checkpoint was written")
                raise TrainingDivergedError(f"{exc}; training stopped and {kept}: lower --lr (or check the "
                                            "dataset), then train again or --resume") from None
            if progress is not None:
                progress(run.step, config.steps, loss)
            if run.step % config.checkpoint_every == 0 or run.step == config.steps:
                last_saved = checkpoint_path(out, run.step)
                save_checkpoint(last_saved, run.payload())
                if keep is not None:
                    prune_checkpoints(out, keep)
        seconds = time.perf_counter() - began
    if last_saved is None:  # resumed a run that had already reached its steps
        last_saved = checkpoint_path(out, run.step)
    done = run.step - start
    tail = run.losses[-LOSS_WINDOW:]
    return TrainSummary(last_saved, config, start, run.step, float(np.mean(tail)) if tail else float("nan"),
                        seconds, done * config.batch_size / seconds if done and seconds > 0 else 0.0,
                        sum(p.numel() for p in run.model.parameters()), data.notes)
