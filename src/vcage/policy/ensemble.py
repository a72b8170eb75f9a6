"""Temporal ensembling of action chunks (Zhao et al. 2023, ACT): how a runner turns chunks into actions.

Without it a runner executes ``n_action_steps`` of each chunk and then predicts the next one from the
observation reached (Diffusion Policy's receding horizon): the arm follows one prediction for a while
and jumps where the next one starts elsewhere. With a :class:`TemporalEnsemble` the runner predicts a
new chunk every ``every`` steps and executes at each step the weighted mean of what every chunk still
covering that step predicted for it, the oldest prediction weighted ``1`` and the ``i``-th newer one
``exp(-decay * i)`` (ACT's weights: a small ``decay`` averages over all of them, a large one trusts
the oldest). The mean is taken in the policy's action space (joint targets, or the tool's position,
rotation columns and gripper), before rotation columns become quaternions again.

No module here imports torch: the chunks arrive as arrays.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from vcage.policy.errors import PolicyError


@dataclass(frozen=True)
class TemporalEnsemble:
    """Predict a chunk every ``every`` control steps; act on the ``decay``-weighted mean of the chunks."""

    every: int = 1
    decay: float = 0.01

    def __post_init__(self) -> None:
        if isinstance(self.every, bool) or not isinstance(self.every, int) or self.every < 1:
            raise PolicyError(f"temporal ensembling predicts a chunk every N >= 1 steps, got "
                              f"every={self.every!r}")
        if isinstance(self.decay, bool) or not isinstance(self.decay, int | float) \
                or not math.isfinite(self.decay) or self.decay < 0:
            raise PolicyError(f"the ensemble's decay must be a finite number >= 0, got {self.decay!r}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class ChunkBlend:
    """The chunks predicted so far in an episode, each aligned at the step it was predicted, and the
    action they agree on for the current step."""

    def __init__(self, spec: TemporalEnsemble, chunk_length: int) -> None:
        if spec.every > chunk_length:
            raise PolicyError(f"temporal ensembling every {spec.every} steps leaves steps that no chunk "
                              f"covers: a chunk runs {chunk_length} steps from the current frame; "
                              f"choose every <= {chunk_length}")
        self.spec = spec
        self.step = 0
        self._chunks: deque[tuple[int, np.ndarray]] = deque()

    def clear(self) -> None:
        self.step = 0
        self._chunks.clear()

    def due(self) -> bool:
        """Whether a chunk is to be predicted at this step."""
        return self.step % self.spec.every == 0

    def add(self, actions: np.ndarray) -> None:
        """A chunk predicted at this step: ``actions[j]`` is its action for step ``step + j``."""
        self._chunks.append((self.step, np.asarray(actions, dtype=np.float64)))

    def next(self) -> np.ndarray:
        """The action of this step (the weighted mean of the predictions covering it); advances a step."""
        while self._chunks and self.step - self._chunks[0][0] >= len(self._chunks[0][1]):
            self._chunks.popleft()
        if not self._chunks:
            raise PolicyError("no predicted chunk covers this step: predict one before acting")
        predictions = np.stack([actions[self.step - start] for start, actions in self._chunks])
        weights = np.exp(-self.spec.decay * np.arange(len(predictions)))
        self.step += 1
        return (weights[:, None] * predictions).sum(axis=0) / weights.sum()
