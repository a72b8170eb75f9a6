"""The VLM critic: an OpenAI-compatible vision model answers a yes/no question about the subtask.

It is shown the top view before the subtask and the top and front views after it, asked whether
the subtask's description is now true, and must answer JSON ``{"success": bool, "reason": str}``.
With ``votes`` > 1 the question is asked several times and the ``rule`` decides (``majority`` or
``all``). A malformed answer, or a request that still fails after the backend's retries, counts
as ``malformed_verdict`` and is recorded in the verdict's details; it never stops the run.
"""

from __future__ import annotations

import json
import re
from typing import Any

from vcage.backends import BackendConfig, ChatBackend, Message, connect
from vcage.critics.base import CRITICS, Critic, CriticConfig, Observation, Verdict
from vcage.errors import BackendError

SYSTEM = ("You verify the outcome of a robot manipulation step on a tabletop from camera images. "
          "Look only at the images. Reply with a JSON object {\"success\": true or false, "
          "\"reason\": \"one short sentence\"} and nothing else.")


class VLMCritic(Critic):
    name = "vlm"

    def __init__(self, backend: ChatBackend, config: CriticConfig | None = None) -> None:
        self.backend = backend
        self.config = config or CriticConfig("vlm")

    def judge(self, obs: Observation) -> Verdict:
        messages = [Message("system", SYSTEM), self._question(obs)]
        votes: list[dict[str, Any]] = []
        for _ in range(self.config.votes):
            votes.append(self._ask(messages))
        yes = sum(v["success"] for v in votes)
        accept = yes == len(votes) if self.config.rule == "all" else yes * 2 > len(votes)
        reasons = "; ".join(str(v["reason"]) for v in votes)
        return Verdict(accept, f"{yes}/{len(votes)} votes yes: {reasons}",
                       {"votes": votes, "malformed": sum(v["malformed"] for v in votes)})

    def _question(self, obs: Observation) -> Message:
        images = []
        names = []
        for label, views, cam in (("before, from above", obs.before, "top"),
                                  ("after, from above", obs.after, "top"),
                                  ("after, from the front", obs.after, "front")):
            if cam in views:
                images.append(views[cam].rgb)
                names.append(label)
        text = (f"The robot just tried to do this: {obs.subtask.description}. Images, in order: "
                f"{'; '.join(names)}. Is the statement \"{obs.subtask.description}\" true in the "
                "images after the step?")
        return Message("user", text, images)

    def _ask(self, messages: list[Message]) -> dict[str, Any]:
        try:
            reply = self.backend.chat(messages, json_mode=True)
        except BackendError as exc:
            return {"success": self.config.malformed_verdict, "reason": f"no answer: {exc}",
                    "malformed": True}
        parsed = parse_answer(reply)
        if parsed is None:
            return {"success": self.config.malformed_verdict,
                    "reason": f"malformed answer {reply[:120]!r}", "malformed": True}
        return {**parsed, "malformed": False}


def parse_answer(reply: str) -> dict[str, Any] | None:
    """``{"success": bool, "reason": str}`` from a reply, tolerating code fences; None if unusable."""
    m = re.search(r"\{.*\}", reply, re.S)
    if m is None:
        return None
    try:
        data = json.loads(m.group(0))
    except json.JSONDecodeError:
        return None
    value = data.get("success", data.get("answer")) if isinstance(data, dict) else None
    if isinstance(value, str) and value.strip().lower() in ("yes", "no", "true", "false"):
        value = value.strip().lower() in ("yes", "true")
    if not isinstance(value, bool):
        return None
    return {"success": value, "reason": str(data.get("reason", ""))[:300]}


ENV_PREFIX = "VCAGE_VLM"  # where the endpoint is read from when the config names none


@CRITICS.register("vlm")
def _vlm(config: CriticConfig) -> Critic:
    return VLMCritic(connect(config.backend or BackendConfig.from_env(ENV_PREFIX)), config)
