"""Stage 1's scene description with an LLM: ``D_scene`` written by the model from the prompt.

The model gets the chosen objects (types and counts, with their colours and what holds what), the
relation vocabulary with its meaning on this table, and the JSON schema of
:class:`~vcage.synthesis.description.SceneDescription`. Its reply is validated like every
description (unknown names, contradictions, supports that do not fit, a table too small) and must
use exactly the chosen objects and honour what the prompt asks for (:mod:`.asked`: every object,
count and relation it names, none it negates); problems are sent back a bounded number of times,
then :class:`SceneDescriptionError` names them.
"""

from __future__ import annotations

import json
from collections import Counter
from typing import Any

from vcage.assets.catalog import CATALOG
from vcage.backends import ChatBackend, Message
from vcage.synthesis.asked import Asked, unmet_in_description
from vcage.synthesis.description import SceneDescription, description_schema, parse_description
from vcage.synthesis.errors import SceneDescriptionError
from vcage.synthesis.llm_chooser import Choice
from vcage.synthesis.llm_reply import MAX_REPAIRS, ReplyRejected, ask_json

RELATIONS = (
    "on(a, b) / inside(a, b): a rests on / in b (b must have a surface / room for it); "
    "left_of(a, b) / right_of(a, b): a is further to the robot's left / right than b (the robot faces "
    "the table; its left is +y); in_front_of(a, b) / behind(a, b): a is nearer to / further from the "
    "robot than b; near(a, b): close together; aligned(a, b): in one row across the table. Optional "
    "distance: metres (0..0.5) of the gap an order relation needs, or of near's slack."
)
EXAMPLE = {"objects": [{"name": "apple", "type": "apple", "color": "red", "scale": 1.0},
                       {"name": "bowl", "type": "bowl", "color": None, "scale": 1.0},
                       {"name": "cup", "type": "cup", "color": None, "scale": 1.0}],
           "relations": [{"kind": "inside", "a": "apple", "b": "bowl", "distance": None},
                         {"kind": "left_of", "a": "cup", "b": "bowl", "distance": None}],
           "text": "A red apple lies inside a bowl; a cup stands to the left of the bowl."}


def object_lines(choice: Choice) -> str:
    lines = []
    for name, count in choice.objects:
        t = CATALOG.get(name)
        holds = [p.kind for p in t.placements]
        what = (" holds objects " + " and ".join("on it" if k == "on" else "inside" for k in holds)
                if holds else "")
        lines.append(f"- {count} x {name}: {t.description}; colours {', '.join(t.colors)}{what}")
    return "\n".join(lines)


def system_prompt(choice: Choice, asked: Asked | None = None) -> str:
    schema = description_schema()
    props = dict(schema.get("properties", {}))  # type: ignore[call-overload]
    props.pop("prompt", None)
    schema = {**schema, "properties": props,
              "required": [r for r in schema.get("required", []) if r != "prompt"]}  # type: ignore[attr-defined]
    return (
        "You describe a tabletop scene for a robot as JSON: the objects (each with a unique name of "
        "letters, digits and underscores, its type, an optional colour among the type's colours, and "
        "scale 0.7..1.3), the spatial relations the user asks for or the scene implies, and one or "
        "two sentences (text) describing the arranged scene for an image model. Use exactly these "
        f"objects, no others:\n{object_lines(choice)}\n\nRelations: {RELATIONS}\n"
        + (f"The prompt asks for: {asked.summary()}. Keep every one of these.\n" if asked and asked.summary()
           else "")
        + "Do not contradict "
        "yourself (an object rests on one thing; no cycles of left_of or in_front_of).\n\n"
        f"JSON schema:\n{json.dumps(schema, separators=(',', ':'))}\n\n"
        f"Example (for other objects):\n{json.dumps(EXAMPLE, separators=(',', ':'))}\n\n"
        "Reply with the JSON object only."
    )


def check_description(data: dict[str, Any], prompt: str, choice: Choice,
                      asked: Asked | None = None) -> SceneDescription:
    desc = parse_description({**data, "prompt": prompt})
    have = Counter(o.type for o in desc.objects)
    want = Counter(dict(choice.objects))
    if have != want:
        extra = sorted((have - want).elements())
        missing = sorted((want - have).elements())
        raise SceneDescriptionError(
            "the objects differ from the chosen ones"
            + (f"; not chosen: {', '.join(extra)}" if extra else "")
            + (f"; missing: {', '.join(missing)}" if missing else "")
            + f"; use exactly: {', '.join(f'{c} x {t}' for t, c in choice.objects)}")
    unmet = unmet_in_description(asked, desc) if asked is not None else []
    if unmet:
        raise SceneDescriptionError("; ".join(unmet))
    return desc


class LLMDescriber:
    """Writes ``D_scene`` through ``backend``; :class:`SceneDescriptionError` when no valid one comes."""

    def __init__(self, backend: ChatBackend, max_repairs: int = MAX_REPAIRS) -> None:
        self.backend = backend
        self.max_repairs = max_repairs

    def describe(self, prompt: str, choice: Choice,
                 asked: Asked | None = None) -> tuple[SceneDescription, int]:
        """The description and the number of replies it took; with ``asked`` (what the prompt
        names) a description that drops an object, a count or a relation of it, or holds an object
        it negates, is sent back, and refused in the end."""
        if not choice.found:
            raise SceneDescriptionError(f"no objects to describe: {choice.no_match}")
        messages = [Message("system", system_prompt(choice, asked)), Message("user", prompt)]
        try:
            return ask_json(self.backend, messages, lambda d: check_description(d, prompt, choice, asked),
                            self.max_repairs, what="scene description")
        except ReplyRejected as exc:
            raise SceneDescriptionError(f"{exc}; rephrase the "
                                        "prompt, try a stronger model, or use the offline describer "
                                        "(no --llm)") from None
