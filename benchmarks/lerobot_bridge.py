"""Serve a trained LeRobot policy's actions over stdin/stdout, one JSON object a line.

Runs inside ``.venv-lerobot`` (``scripts/lerobot-env.sh``): it imports LeRobot and torch, never vcage.
``benchmarks/lerobot_reference.py`` starts it as a subprocess and rolls the policy out in vcage's
evaluation environment through it. The checkpoint is the ``pretrained_model`` directory that
``lerobot-train`` writes (``config.json``, ``model.safetensors`` and the policy's pre/post-processor
pipelines, which normalize the observations and unnormalize the actions with the dataset's stats).

Protocol (after one line ``{"ready": true, "input_features": [...], "lerobot": VERSION, ...}``):

- ``{"reset": true}`` (optionally ``"episode": k``): empties the policy's observation and action
  queues and reseeds torch from ``(--seed, k)``, so an episode's sampling does not depend on the
  episodes before it; answers ``{"ok": true}``;
- ``{"observation": {"observation.state": [...], "observation.environment_state": [...]}}``: answers
  ``{"action": [floats]}`` from ``select_action`` (the policy's next action, unnormalized);
- end of input: exits. A malformed request answers ``{"error": "..."}`` and the bridge goes on.

    .venv-lerobot/bin/python benchmarks/lerobot_bridge.py CHECKPOINT/pretrained_model --seed 0
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import IO, Any

os.environ.setdefault("HF_HUB_OFFLINE", "1")  # a local checkpoint: never ask the hub

import numpy as np
import torch


class Bridge:
    """A LeRobot policy with its processors, answering one request at a time."""

    def __init__(self, checkpoint: Path, seed: int) -> None:
        import lerobot
        from lerobot.configs import PreTrainedConfig
        from lerobot.policies import get_policy_class, make_pre_post_processors

        self.seed = seed
        config = PreTrainedConfig.from_pretrained(checkpoint)
        config.device = "cpu"
        self.policy = get_policy_class(config.type).from_pretrained(checkpoint, config=config)
        self.policy.eval()
        self.preprocessor, self.postprocessor = make_pre_post_processors(
            config, pretrained_path=str(checkpoint),
            preprocessor_overrides={"device_processor": {"device": "cpu"}})
        self.features: dict[str, int] = {
            key: int(np.prod(feature.shape)) for key, feature in config.input_features.items()}
        self.banner = {"ready": True, "input_features": list(self.features), "type": config.type,
                       "lerobot": lerobot.__version__, "torch": torch.__version__,
                       "action_dim": int(np.prod(config.output_features["action"].shape))}
        self.reset(0)

    def reset(self, episode: int) -> None:
        torch.manual_seed(int(np.random.SeedSequence([self.seed, episode]).generate_state(1)[0]))
        self.policy.reset()

    def act(self, observation: dict[str, Any]) -> list[float]:
        batch: dict[str, Any] = {}
        for key, size in self.features.items():
            value = torch.as_tensor(np.asarray(observation[key], dtype=np.float32))
            if value.shape != (size,):
                raise ValueError(f"{key}: expected {size} numbers, got shape {tuple(value.shape)}")
            batch[key] = value
        with torch.inference_mode():
            action = self.postprocessor(self.policy.select_action(self.preprocessor(batch)))
        return [float(x) for x in action.reshape(-1).tolist()]

    def answer(self, request: dict[str, Any]) -> dict[str, Any]:
        if request.get("reset"):
            self.reset(int(request.get("episode", 0)))
            return {"ok": True}
        if isinstance(request.get("observation"), dict):
            return {"action": self.act(request["observation"])}
        raise ValueError("a request is {'reset': true} or {'observation': {...}}")


def serve(bridge: Bridge, requests: IO[str], replies: IO[str]) -> None:
    def send(message: dict[str, Any]) -> None:
        replies.write(json.dumps(message) + "\n")
        replies.flush()

    send(bridge.banner)
    for line in requests:
        if not line.strip():
            continue
        try:
            reply = bridge.answer(json.loads(line))
        except (ValueError, KeyError, TypeError) as exc:
            reply = {"error": f"{type(exc).__name__}: {exc}"}
        send(reply)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("checkpoint", type=Path, help="a pretrained_model directory lerobot-train wrote")
    parser.add_argument("--seed", type=int, default=0, help="seeds the diffusion sampling (with the episode)")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)
    replies, sys.stdout = sys.stdout, sys.stderr  # the protocol owns stdout; library prints go to stderr
    serve(Bridge(args.checkpoint, args.seed), sys.stdin, replies)


if __name__ == "__main__":
    main()
