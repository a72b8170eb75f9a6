"""Stage 1 with an LLM: the model chooses the scene's objects from the retrieval shortlist.

The shortlist (catalog types ranked by :mod:`.retrieval`, with their descriptions) goes to the
model, which answers ``{"objects": [{"type": ..., "count": n}], "no_match": null}`` naming shortlist
types only, or ``{"objects": [], "no_match": "why"}`` when none suits the request: "no suitable
object" is an answer. Names outside the shortlist, duplicates, both or neither, and a choice that
leaves out an object the prompt names (or takes fewer than its count, or one it negates) are sent
back as problems (:func:`~vcage.synthesis.llm_reply.ask_json`), a bounded number of times.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from vcage.assets.catalog import CATALOG
from vcage.backends import ChatBackend, Message
from vcage.synthesis.asked import Asked, unmet_in_choice
from vcage.synthesis.description import MAX_OBJECTS
from vcage.synthesis.errors import PromptError
from vcage.synthesis.llm_reply import MAX_REPAIRS, ReplyRejected, ask_json

SHORTLIST = 16  # candidate types shown to the model
MAX_COUNT = 4  # copies of one type


class _Chosen(BaseModel):
    model_config = ConfigDict(extra="forbid")
    type: str
    count: int = Field(default=1, ge=1, le=MAX_COUNT)


class _ChoiceReply(BaseModel):
    model_config = ConfigDict(extra="forbid")
    objects: list[_Chosen] = Field(default_factory=list)
    no_match: str | None = None


@dataclass(frozen=True)
class Choice:
    """The model's choice: ``(type, count)`` pairs from the shortlist, or none and ``no_match``."""

    objects: tuple[tuple[str, int], ...]
    no_match: str | None
    shortlist: tuple[str, ...]
    replies: int = 1

    @property
    def found(self) -> bool:
        return bool(self.objects)

    def to_dict(self) -> dict[str, Any]:
        return {"objects": [{"type": t, "count": c} for t, c in self.objects], "no_match": self.no_match,
                "shortlist": list(self.shortlist), "replies": self.replies}


def candidate_lines(names: Sequence[str]) -> str:
    lines = []
    for name in names:
        t = CATALOG.get(name)
        lines.append(f"- {name} ({t.category}): {t.description}")
    return "\n".join(lines)


def system_prompt(shortlist: Sequence[str]) -> str:
    return (
        "You choose the objects of a tabletop scene for a robot. The user describes a scene; choose "
        "the objects it needs from the candidates below, which are the only objects that exist. Answer "
        'with a JSON object {"objects": [{"type": <candidate name>, "count": <1..'
        f'{MAX_COUNT}>}}], "no_match": null}}, using the candidate names exactly, each at most once, at '
        f"most {MAX_OBJECTS} objects in all. If no candidate suits the request (it asks for objects "
        'none of them is), answer {"objects": [], "no_match": "<what is missing>"}.\n\n'
        f"Candidates:\n{candidate_lines(shortlist)}\n\nReply with the JSON object only."
    )


def check_choice(data: dict[str, Any], shortlist: Sequence[str],
                 asked: Asked | None = None) -> tuple[tuple[tuple[str, int], ...], str | None]:
    reply = _ChoiceReply.model_validate(data)
    if reply.objects and reply.no_match:
        raise ValueError("give either objects or no_match, not both")
    if not reply.objects and not (reply.no_match or "").strip():
        raise ValueError("no objects chosen and no no_match reason given: choose objects or say why none")
    names = [c.type for c in reply.objects]
    unknown = [n for n in names if n not in shortlist]
    if unknown:
        raise ValueError(f"{', '.join(repr(n) for n in unknown)} is not a candidate; use only these names: "
                         f"{', '.join(shortlist)}")
    if len(set(names)) != len(names):
        raise ValueError("a candidate is named twice: name each once and use count for copies")
    total = sum(c.count for c in reply.objects)
    if total > MAX_OBJECTS:
        raise ValueError(f"{total} objects in all, more than the {MAX_OBJECTS} a scene may hold")
    chosen = tuple((c.type, c.count) for c in reply.objects)
    unmet = unmet_in_choice(asked, chosen) if asked is not None and chosen else []
    if unmet:
        raise ValueError("; ".join(unmet))
    return chosen, (reply.no_match or None)


class LLMChooser:
    """Chooses from a shortlist through ``backend``; :class:`PromptError` when no valid answer comes."""

    def __init__(self, backend: ChatBackend, max_repairs: int = MAX_REPAIRS) -> None:
        self.backend = backend
        self.max_repairs = max_repairs

    def choose(self, prompt: str, shortlist: Sequence[str], asked: Asked | None = None) -> Choice:
        """The model's choice; with ``asked`` (what the prompt names) the objects it names come
        first in the shortlist and a choice that drops one, takes fewer than its count or takes
        one the prompt negates is sent back."""
        groups = asked.objects if asked is not None else ()
        over = [f"{o.count} x {o.type}" for o in groups if o.count > MAX_COUNT]
        if over:
            raise PromptError(f"the prompt asks for {', '.join(over)}; the LLM chooser takes at most "
                              f"{MAX_COUNT} of one type: ask for fewer, or use the offline describer "
                              "(no --llm)")
        named = [o.type for o in groups]
        names = tuple(dict.fromkeys(n for n in [*named, *shortlist] if n in CATALOG))
        names = names[:max(SHORTLIST, len(set(named)))]
        if not names:
            return Choice((), "retrieval found no candidate object for the request", names, 0)
        messages = [Message("system", system_prompt(names)), Message("user", prompt)]
        try:
            (objects, no_match), replies = ask_json(self.backend, messages,
                                                    lambda d: check_choice(d, names, asked),
                                                    self.max_repairs, what="choice of objects")
        except ReplyRejected as exc:
            raise PromptError(f"{exc}; try a stronger model "
                              "or the offline retrieval (no --llm)") from None
        return Choice(objects, no_match, names, replies)
