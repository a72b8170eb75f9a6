"""What a backend has cost so far, as the servers reported it."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any


@dataclass
class Usage:
    """Running totals of one backend: requests sent, retries, waits and tokens the server reported."""

    requests: int = 0
    retries: int = 0
    failures: int = 0
    wait_s: float = 0.0
    prompt_tokens: int = 0
    completion_tokens: int = 0

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)
