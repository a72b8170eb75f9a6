"""Critics judge each subtask's outcome: the offline image critic, VLM critics, and the oracle.

Importing the package registers the built-in critics in ``CRITICS``.
"""

from vcage.critics import image, oracle, vlm  # noqa: F401  (register the built-in critics)
from vcage.critics.base import (
    CRITICS,
    Critic,
    CriticConfig,
    Observation,
    Reason,
    Recorder,
    Verdict,
    View,
    make_critic,
)

__all__ = ["CRITICS", "Critic", "CriticConfig", "Observation", "Reason", "Recorder", "Verdict", "View",
           "make_critic"]
