"""The order training draws samples in: one seeded permutation per epoch (no torch).

The batch at a position depends only on the seed and the position, so a resumed run that restores
the position draws exactly the batches the uninterrupted run would have drawn.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from vcage.errors import ConfigError


class BatchSampler:
    """Batches of ``batch_size`` sample indices out of ``n``, epoch after epoch without replacement
    within an epoch (a batch may span two epochs)."""

    def __init__(self, n: int, batch_size: int, seed: int) -> None:
        if n < 1:
            raise ConfigError("the sampler needs at least one sample")
        self.n, self.batch_size, self.seed = n, batch_size, seed
        self.position = 0  # samples drawn so far
        self._epoch, self._order = -1, np.zeros(0, dtype=np.int64)

    def _permutation(self, epoch: int) -> np.ndarray:
        if epoch != self._epoch:
            self._epoch = epoch
            self._order = np.random.default_rng([self.seed, epoch]).permutation(self.n)
        return self._order

    def next_batch(self) -> np.ndarray:
        epochs, offsets = np.divmod(self.position + np.arange(self.batch_size), self.n)
        out = np.empty(self.batch_size, dtype=np.int64)
        for epoch in np.unique(epochs):
            here = epochs == epoch
            out[here] = self._permutation(int(epoch))[offsets[here]]
        self.position += self.batch_size
        return out

    def state_dict(self) -> dict[str, Any]:
        return {"position": self.position, "n": self.n, "batch_size": self.batch_size, "seed": self.seed}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        if (state["n"], state["batch_size"], state["seed"]) != (self.n, self.batch_size, self.seed):
            raise ConfigError(f"the saved sampler drew from {state['n']} samples in batches of "
                              f"{state['batch_size']} with seed {state['seed']}; this run has {self.n}, "
                              f"{self.batch_size}, {self.seed}")
        self.position = int(state["position"])
