"""Ask a chat model for JSON, check it, and send the problems back a bounded number of times.

The loop the LLM planner uses (:mod:`vcage.planning.llm`), for the synthesis stages: each reply is
parsed (code fences stripped) and given to ``check``, which returns the value or raises
``ValueError`` / ``ValidationError`` naming what is wrong; the problems go back to the model with its
reply, at most ``max_repairs`` times. Then :class:`ReplyRejected` carries the last problems, and the
caller raises its stage's typed error.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any, TypeVar

from pydantic import ValidationError

from vcage.backends import ChatBackend, Message
from vcage.planning.llm import describe_problems, strip_fences
from vcage.synthesis.errors import SynthesisError

T = TypeVar("T")
MAX_REPAIRS = 2
MAX_PROBLEMS = 8


class ReplyRejected(SynthesisError):  # noqa: N818 - what happened to the replies
    """Every reply of the model was refused; ``problems`` are the last reply's, ``replies`` how many."""

    def __init__(self, message: str, problems: str, replies: int) -> None:
        super().__init__(message)
        self.problems = problems
        self.replies = replies


def problems(exc: Exception) -> str:
    """What is wrong, in words a model can act on."""
    return describe_problems(exc, root="reply", limit=MAX_PROBLEMS)


def ask_json(backend: ChatBackend, messages: list[Message], check: Callable[[dict[str, Any]], T],
             max_repairs: int = MAX_REPAIRS, what: str = "reply") -> tuple[T, int]:
    """The checked value of the model's JSON object, and how many replies it took."""
    messages = list(messages)
    errors = ""
    for n in range(1, max_repairs + 2):
        reply = backend.chat(messages, json_mode=True)
        try:
            data = json.loads(strip_fences(reply))
            if not isinstance(data, dict):
                raise ValueError(f"the reply is a JSON {type(data).__name__}, not an object")
            return check(data), n
        except (ValueError, ValidationError, SynthesisError) as exc:
            errors = problems(exc)
        messages += [Message("assistant", reply),
                     Message("user", f"That reply is not a valid {what}: {errors}\nReply again with only "
                                     "the corrected JSON object.")]
    raise ReplyRejected(f"the LLM gave no valid {what} in {max_repairs + 1} replies; last problems: "
                        f"{errors}", errors, max_repairs + 1)
