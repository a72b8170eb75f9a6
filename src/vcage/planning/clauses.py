"""How an instruction splits into clauses, and which clauses are explicit steps.

``split_clauses`` cuts an instruction at the words that end a step ("then", "after that", ";",
sentences), and at commas or "and" only before a command verb or a placing step that leaves out its
verb ("put the remote in the box and the marker in the cup"); "X after putting Y ..." is put in
execution order. The patterns of the step shapes (placing, pressing, drawers, hanging, turning to
face) are read by :mod:`vcage.planning.steps`.
"""

from __future__ import annotations

import re

from vcage.planning.lexicon import find_mentions, words

# separators that always end a step; weak ones (commas, "and") only before a verb or an elided step
_STRONG = re.compile(r"\s*(?:;|[.!?](?:\s+|$)|,?\s*\b(?:and\s+)?then\b,?|,?\s*\b(?:and\s+)?after\s+that\b,?"
                     r"|,?\s*\bafterwards\b,?)\s*")
_WEAK = re.compile(r"(\s*,\s*(?:and\s+)?|\s+and\s+)")
_PREFIX = re.compile(r"^(?:(?:please|kindly|now|first|firstly|next|finally|lastly|also|and|robot)\b,?\s*"
                     r"|(?:can|could|would|will)\s+you\s+(?:please\s+)?"
                     r"|i\s+(?:want|need|would\s+like|'?d\s+like)\s+you\s+to\s+)+")
_PLACE_VERBS = "put|place|move|set|drop|lay|stack|nest|bring|carry"
_PRESS_VERBS = "press|push|click|ring|hit|tap|silence|flip|toggle|turn on|turn off|switch on|switch off|use"
_DRAWER_VERBS = "open|pull open|pull out|close|shut"
_REL = r"on top of|onto|on|into|inside of|inside|in"
_PLACE = re.compile(rf"^(?:{_PLACE_VERBS})\s+(?P<obj>.+?)\s+(?P<rel>{_REL})\s+(?P<target>.+)$")
_ELIDED = re.compile(rf"^(?P<obj>.+?)\s+(?P<rel>{_REL})\s+(?P<target>.+)$")  # "..., the cup on the coaster"
_PRESS = re.compile(rf"^(?P<verb>{_PRESS_VERBS})\s+(?P<obj>.+)$")
# "close up the office" and "shut down the laptop" are not about a drawer
_DRAWER = re.compile(rf"^(?P<verb>{_DRAWER_VERBS})\s+(?!(?:up|down|off)\b)(?P<obj>.+)$")
# "turn the QR code board to face me": a step of its own, read before the press verbs ("turn on ...")
_FACE = re.compile(r"^(?:turn|rotate)\s+(?P<obj>.+?)\s+(?:a?round\s+)?(?:to\s+face|towards?)\s+"
                   r"(?:me|us|the\s+robot)$")
_HANG = re.compile(r"^hang\s+(?P<obj>.+?)\s+(?:up\s+)?(?:on|onto|from)\s+(?P<target>.+)$")
_COMMAND = re.compile(rf"^(?:{_PLACE_VERBS}|{_PRESS_VERBS}|{_DRAWER_VERBS}|switch|turn|rotate|hang)\b")
_GERUNDS = {"putting": "put", "placing": "place", "moving": "move", "setting": "set", "dropping": "drop",
            "laying": "lay", "stacking": "stack", "nesting": "nest", "pressing": "press", "pushing": "push",
            "ringing": "ring", "hitting": "hit", "tapping": "tap", "silencing": "silence", "flipping": "flip"}
_ORDER = re.compile(r"^(?P<a>.+?)\s+(?P<when>after|before)\s+(?P<g>[a-z]+ing)\s+(?P<rest>.+)$")


def _strip(clause: str) -> str:
    clause = _PREFIX.sub("", clause.strip(" ,.!?")).strip(" ,.!?")
    return re.sub(r"\s*,?\s*please$", "", clause)


def split_clauses(text: str) -> list[str]:
    """The clauses of ``text``, lower-cased, in execution order."""
    clauses: list[str] = []
    for part in _STRONG.split(text.lower()):
        part = _strip(part)
        if not part:
            continue
        pieces = _WEAK.split(part)  # piece, separator, piece, ...
        first = _strip(pieces[0])
        merged = [_elided(first, clauses[-1]) if clauses else first]
        for sep, raw in zip(pieces[1::2], pieces[2::2], strict=True):
            piece = _strip(raw)
            if _COMMAND.match(piece) and merged[-1]:
                merged.append(piece)
            elif _elided(piece, merged[-1]) != piece:
                merged.append(_elided(piece, merged[-1]))
            else:
                merged[-1] = f"{merged[-1]}{sep}{raw}"  # a list inside one step: "the red and blue block"
        for clause in filter(None, merged):
            m = _ORDER.match(clause)
            if m and m["g"] in _GERUNDS:  # "press the bell after putting the cup on the coaster"
                later = f"{_GERUNDS[m['g']]} {m['rest']}"
                clauses += [later, m["a"]] if m["when"] == "after" else [m["a"], later]
            else:
                clauses.append(clause)
    return clauses


def _elided(piece: str, previous: str) -> str:
    """``piece`` with the verb of ``previous`` if it is a placing step without its verb
    ("put the remote in the box and the marker in the cup")."""
    m = _ELIDED.match(piece)
    if (m and not _COMMAND.match(piece) and _PLACE.match(previous)
            and find_mentions(words(m["obj"]), all_objects=True)):
        return f"{previous.split(' ', 1)[0]} {piece}"
    return piece


def _is_step(clause: str) -> bool:
    """Whether ``clause`` is (or tries to be) an explicit step: a step's shape, or a command verb
    (opening or closing a drawer among them: "shut everything down" is not a step) and a catalog
    object."""
    if _PLACE.match(clause) or _PRESS.match(clause):
        return True
    return bool(_COMMAND.match(clause) and find_mentions(words(clause)))


__all__ = ["split_clauses"]
