"""A trained policy acting in an environment: observation window in, one action out per step.

The runner keeps the last ``(n_obs_steps - 1) * obs_stride + 1`` observations (the first one
repeated after a reset, as training pads the start of an episode), of which the policy reads every
``obs_stride``-th back from the current one, and a queue of actions: when the queue is empty it predicts
a chunk of ``horizon`` actions from the window and queues the ``n_action_steps`` starting at the
current frame (index ``n_obs_steps - 1`` of the chunk), as Diffusion Policy executes them. With a
:class:`~vcage.policy.ensemble.TemporalEnsemble` it predicts a chunk every ``every`` steps instead
and acts on the weighted mean of the chunks covering the step (ACT's temporal ensembling).

A subtask-conditioned policy also keeps the subtask it is in: before each chunk its classifier
names the subtask of the window, and the runner moves on to it if it is a later one. It never goes
back within an episode: a plan's subtasks are done in order, and a state in which an earlier
subtask's goal holds again (the mouse still on its pad while the bell is pressed) should not send
the arm back to it.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import torch

from vcage.policy.config import TrainConfig
from vcage.policy.dataset import FeatureSpec
from vcage.policy.encoding import VectorEncoder
from vcage.policy.ensemble import ChunkBlend, TemporalEnsemble
from vcage.policy.errors import PolicyError
from vcage.policy.models import Policy, make_policy, randn
from vcage.policy.normalize import Normalizer


class PolicyRunner:
    """Acts with the EMA weights of a checkpoint (as :func:`vcage.policy.checkpoint.load_checkpoint`
    returns it); ``seed`` fixes the diffusion sampler's noise; ``ensemble`` turns on temporal
    ensembling of the chunks (None: execute ``n_action_steps`` of each)."""

    def __init__(self, checkpoint: Mapping[str, Any], *, device: str = "cpu", seed: int = 0,
                 ensemble: TemporalEnsemble | None = None) -> None:
        self.config = TrainConfig.from_dict(checkpoint["config"])
        self.obs_features = tuple(FeatureSpec.from_dict(f) for f in checkpoint["obs_features"])
        self.action_feature = FeatureSpec.from_dict(checkpoint["action_feature"])
        self.obs_norm = Normalizer.from_dict(checkpoint["normalization"]["obs"])
        self.action_norm = Normalizer.from_dict(checkpoint["normalization"]["action"])
        self.device = torch.device(device)
        self.encoder = VectorEncoder(self.obs_features, self.config.rotations, self.config.relative_objects)
        self.action_encoder = VectorEncoder([self.action_feature], self.config.rotations)
        self.model: Policy = make_policy(self.config, self.encoder.size, self.action_encoder.size,
                                         int(checkpoint.get("subtasks", 0)))
        try:
            self.model.load_state_dict(checkpoint["ema"]["model"])
        except (RuntimeError, KeyError, TypeError) as exc:
            raise PolicyError(f"the checkpoint's weights do not fit its own configuration ({exc}); it is "
                              "damaged: train again") from None
        self.model.to(self.device).eval()
        self.generator = torch.Generator().manual_seed(seed)
        self.span = (self.config.n_obs_steps - 1) * self.config.obs_stride + 1  # frames the window reaches
        self._window: deque[np.ndarray] = deque(maxlen=self.span)
        self._queue: deque[np.ndarray] = deque()
        self.subtask = 0  # the subtask a subtask-conditioned policy is in (always 0 for others)
        chunk_length = self.config.horizon - (self.config.n_obs_steps - 1)  # steps from the current frame on
        self.blend = ChunkBlend(ensemble, chunk_length) if ensemble is not None else None

    @property
    def observation_keys(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.obs_features)

    def reset(self, seed: int | None = None) -> None:
        """Forget the observation window and the queued actions (call at every episode start);
        ``seed`` restarts the sampler's noise, so an episode does not depend on the ones before."""
        self._window.clear()
        self._queue.clear()
        if self.blend is not None:
            self.blend.clear()
        self.subtask = 0
        if seed is not None:
            self.generator.manual_seed(seed)

    def observation_vector(self, obs: Mapping[str, Any]) -> np.ndarray:
        """The policy's input for an environment observation: its features side by side, encoded."""
        return self.encoder(np.concatenate([f.select(np.asarray(obs[f.feature], dtype=np.float32).reshape(-1))
                                            for f in self.obs_features]))

    def act(self, obs: Mapping[str, Any]) -> np.ndarray:
        """The action for this step of the episode, given the environment's observation."""
        return act_together([self], [obs])[0]

    def _observe(self, obs: Mapping[str, Any]) -> None:
        vector = self.obs_norm.normalize(self.observation_vector(obs))
        if not self._window:
            self._window.extend([vector] * self.span)
        else:
            self._window.append(vector)

    def window(self) -> np.ndarray:
        """The observation window the policy reads now (n_obs_steps, size), oldest frame first."""
        return np.stack(list(self._window)[::self.config.obs_stride])

    def due(self) -> bool:
        """Whether this step needs a new chunk (its queue is empty, or the ensemble predicts now)."""
        return self.blend.due() if self.blend is not None else not self._queue

    def _take_chunk(self, chunk: np.ndarray) -> None:
        start = self.config.n_obs_steps - 1
        if self.blend is not None:  # the whole chunk from the current frame on, still encoded
            self.blend.add(self.action_norm.unnormalize(chunk[start:]))
            return
        executed = self.action_norm.unnormalize(chunk[start:start + self.config.n_action_steps])
        self._queue.extend(self.action_encoder.decode(executed))

    def _next_action(self) -> np.ndarray:
        if self.blend is not None:
            return self.action_encoder.decode(self.blend.next().astype(np.float32))
        return self._queue.popleft()


def act_together(runners: Sequence[PolicyRunner],
                 observations: Sequence[Mapping[str, Any]]) -> list[np.ndarray]:
    """One action for each of ``runners`` (episodes of the same checkpoint) given its observation.

    The runners due a chunk (:meth:`PolicyRunner.due`) sample their chunks as one batch through the
    first runner's network, each starting from noise drawn from its own generator, so an episode's
    noise does not depend on the others. One runner alone is :meth:`PolicyRunner.act`; a batch's
    outputs can differ from one-at-a-time passes in the last bits of the floating-point arithmetic."""
    for runner, obs in zip(runners, observations, strict=True):
        runner._observe(obs)
    due = [r for r in runners if r.due()]
    if due:
        lead = runners[0]
        windows = torch.from_numpy(np.stack([r.window() for r in due])).to(lead.device)
        shape = (1, lead.config.horizon, lead.action_encoder.size)
        noise = torch.cat([randn(shape, r.generator, windows) for r in due])
        subtask = None
        if lead.model.subtasks:
            with torch.no_grad():
                named = lead.model.classify(windows).argmax(dim=1).tolist()
            for runner, k in zip(due, named, strict=True):
                runner.subtask = max(runner.subtask, int(k))
            subtask = torch.tensor([r.subtask for r in due], device=lead.device)
        chunks = lead.model.predict_from(windows, noise, subtask).cpu().numpy()
        for runner, chunk in zip(due, chunks, strict=True):
            runner._take_chunk(chunk)
    return [r._next_action() for r in runners]
