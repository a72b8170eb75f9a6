"""The objects an instruction names: catalog types by name, alias and plural, with colour and size.

``find_mentions`` reads every catalog object a text names, so that a planner can check that its plan
contains them all. ``parse_phrase`` reads one argument of an explicit step ("the small red bowl",
"its stand") strictly: exactly one object, no plural, no word it does not understand.

A word that is both a colour and an object type ("orange") is the object when it is the head noun
("the orange") and a colour when an object noun follows it ("the orange block", "the orange and
blue blocks"). Words that are also verbs ("can", "switch", "stamp", ...) are objects only after a
determiner, a colour, a size or a preposition ("the can", "on the stamp mat"), not in "can you" or
"stamp the papers".
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from vcage.assets.catalog import CATALOG
from vcage.errors import PlanningError
from vcage.planning.language import bounded

if TYPE_CHECKING:
    from vcage.planning.schema import PlanObject

# spoken names -> catalog types (besides the type names themselves, with spaces)
ALIASES = {
    "pad": "mouse_pad", "mousepad": "mouse_pad", "stand": "object_stand", "display stand": "object_stand",
    "phone stand": "phone_stand", "charging stand": "phone_stand", "mat": "stamp_mat", "ink mat": "stamp_mat",
    "ink pad": "stamp_mat", "stamp": "seal", "clock": "alarm_clock", "alarm": "alarm_clock",
    "light switch": "switch", "cellphone": "phone", "smartphone": "phone", "cube": "block",
    "loaf": "bread", "mobile": "phone", "cell phone": "phone", "service bell": "bell",
    "ball": "tennis_ball", "car": "toy_car", "glue": "glue_stick", "card": "playing_card",
    "cereal": "cereal_box", "rubiks cube": "rubik_cube", "rubik": "rubik_cube", "rubiks": "rubik_cube",
    "rolling pin": "roller", "qr code": "qr_board", "qr board": "qr_board", "qr code board": "qr_board",
    "deck": "card_deck", "deck of cards": "card_deck", "pill": "pill_bottle",
    "medicine bottle": "pill_bottle",
    "french fries": "fries", "hamburger": "burger", "sneaker": "shoe", "trash can": "dustbin",
    "trash bin": "dustbin", "bin": "dustbin", "scale": "kitchen_scale", "mug rack": "mug_rack",
    "rack": "mug_rack", "desk fan": "fan", "drawer": "cabinet",
}
# a name that may denote more than one type: a plan containing either covers it; in a step the
# first is meant unless the context says otherwise (a phone's stand is the phone stand)
ALTERNATIVES: dict[str, tuple[str, ...]] = {"stand": ("object_stand", "phone_stand")}
SIZES: dict[str, float | None] = {"small": 0.85, "little": 0.85, "smaller": 0.85, "large": None, "big": None,
                                  "larger": None, "bigger": None}
COLOURS = frozenset(c for t in CATALOG.values() for c in t.colors)
DETERMINERS = frozenset({"the", "a", "an", "my", "your", "our", "his", "her", "their", "this", "that",
                         "these", "those", "some", "its"})
OTHER = frozenset({"other", "another"})
PREPOSITIONS = frozenset({"on", "in", "into", "onto", "inside", "with", "from", "of", "under", "near",
                          "beside", "by", "at", "over", "next", "behind"})
# catalog nouns that are also verbs: objects only where an object can stand (see the module doc)
VERBISH = frozenset({"can", "switch", "stamp", "seal", "tape", "block", "book", "stand", "box", "phone",
                     "dice", "pot", "mat", "hammer", "fan", "scale", "shoe", "bin", "deck", "rack"})
_IRREGULAR_PLURALS = {"mouse": "mice"}


def _plural(word: str) -> str:
    if word in _IRREGULAR_PLURALS:
        return _IRREGULAR_PLURALS[word]
    return word + ("es" if word.endswith(("s", "x", "ch", "sh", "z")) else "s")


def _nouns() -> dict[tuple[str, ...], tuple[str, bool]]:
    """Word sequence -> (type, plural) for every name and alias of every catalog type."""
    names = {t.replace("_", " "): t for t in CATALOG.names()} | ALIASES
    out: dict[tuple[str, ...], tuple[str, bool]] = {}
    for spoken, type_ in names.items():
        words = tuple(spoken.split())
        out[words] = (type_, False)
        if type_ != "dice":  # "dice" is already the plural
            out.setdefault((*words[:-1], _plural(words[-1])), (type_, True))
    return out


NOUNS = _nouns()
_MAX_WORDS = max(len(k) for k in NOUNS)
NOUN_WORDS = frozenset(w for k in NOUNS for w in k)


def words(text: str) -> list[str]:
    """Lower-case words and the punctuation that separates them (``rubik's`` -> ``rubiks``)."""
    text = re.sub(r"\brubik'?s\b", "rubiks", text.lower().replace("\u2019", "'"))
    return re.findall(r"[a-z0-9]+|[,;.!?]", text)


def determiner_phrases(ws: list[str], stops: Callable[[str], bool],
                       longest: int = 3) -> list[tuple[str, list[str]]]:
    """Phrases a determiner introduces in the words ``ws`` ("the laptop", "a blue mug"): each
    determiner with up to ``longest`` words after it, ending at punctuation, another determiner or
    a word ``stops`` accepts; determiners with no word after them are left out."""
    out = []
    for i, w in enumerate(ws):
        if w not in DETERMINERS:
            continue
        run = []
        for nxt in ws[i + 1:i + 1 + longest]:
            if not nxt.isalnum() or nxt in DETERMINERS or stops(nxt):
                break
            run.append(nxt)
        if run:
            out.append((w, run))
    return out


@dataclass(frozen=True)
class Mention:
    """One object named in a text: words ``[start, end)`` (the noun), its colour and size words."""

    start: int
    end: int
    noun: str
    type: str
    accepts: tuple[str, ...]
    colours: tuple[str, ...] = ()
    size: float | None = None
    sized: bool = False
    plural: bool = False
    first: int = -1  # index of its first modifier (colour or size word); start when none

    def label(self) -> str:
        return " ".join((*self.colours, self.noun))

    def covered_by(self, type_: str, colour: str | None) -> bool:
        return type_ in self.accepts and (not self.colours or colour in self.colours)


def _noun_at(ws: list[str], i: int) -> tuple[int, str, bool] | None:
    """The longest catalog noun starting at word ``i``: (end, type, plural)."""
    for n in range(min(_MAX_WORDS, len(ws) - i), 0, -1):
        hit = NOUNS.get(tuple(ws[i:i + n]))
        if hit is not None:
            return i + n, hit[0], hit[1]
    return None


def _is_colour_here(ws: list[str], i: int, end: int) -> bool:
    """Whether the colour-and-noun word ``ws[i]`` is used as a colour: an object noun follows it,
    directly or after a list of colours ("the orange and blue blocks")."""
    if _noun_at(ws, end) is not None:
        return True
    k = end
    while k < len(ws) and (ws[k] in (",", "and", "or") or (ws[k] in COLOURS and ws[k] not in NOUN_WORDS)):
        k += 1
    return k > end and ws[k - 1] in COLOURS and _noun_at(ws, k) is not None


def _object_position(ws: list[str], i: int) -> bool:
    prev = ws[i - 1] if i > 0 else ""
    return prev in DETERMINERS or prev in COLOURS or prev in SIZES or prev in PREPOSITIONS or prev in OTHER


def find_mentions(ws: list[str], all_objects: bool = False) -> list[Mention]:
    """Every catalog object the words name, in order (``all_objects``: no word is read as a verb)."""
    out: list[Mention] = []
    i = 0
    while i < len(ws):
        hit = _noun_at(ws, i)
        if hit is None:
            i += 1
            continue
        end, type_, plural = hit
        single = end - i == 1
        if single and ws[i] in COLOURS and _is_colour_here(ws, i, end):
            i += 1  # "orange" in "the orange block": the block's colour
            continue
        if single and not all_objects and ws[i] in VERBISH and not _object_position(ws, i):
            i += 1  # "can you", "stamp the papers", "switch everything off"
            continue
        colours: list[str] = []
        size: float | None = None
        sized = False
        j = i - 1
        while j >= 0 and (ws[j] in COLOURS or ws[j] in SIZES or (colours and ws[j] in (",", "and", "or"))):
            if ws[j] in COLOURS:
                colours.insert(0, ws[j])
            elif ws[j] in SIZES:
                size, sized = SIZES[ws[j]], True
            j -= 1
        while j + 1 < i and ws[j + 1] in (",", "and", "or"):
            j += 1  # a separator before the first colour is not part of the mention
        noun = " ".join(ws[i:end])
        accepts = ALTERNATIVES.get(noun, (type_,))
        out.append(Mention(i, end, noun, type_, accepts, tuple(colours), size, sized, plural, first=j + 1))
        i = end
    return out


@dataclass(frozen=True)
class ObjectRef:
    """One object an explicit step names."""

    type: str
    accepts: tuple[str, ...]
    colour: str | None
    size: float | None
    sized: bool
    other: bool  # "the other bowl": a new object even if one of the type is known
    text: str


def known_objects() -> str:
    return ", ".join(n.replace("_", " ") for n in CATALOG.names())


def listed(items: list[str], limit: int = 8) -> str:
    """``items`` joined, at most ``limit`` of them (then how many there are)."""
    shown = ", ".join(items[:limit]) or "none"
    return shown + (f", ... ({len(items)} in all)" if len(items) > limit else "")


def parse_phrase(phrase: str, clause: str) -> ObjectRef:
    """The one object ``phrase`` names, or :class:`PlanningError` saying why it is not one. A
    message quotes at most 200 characters of the user's text: 60 of the phrase, 80 of the clause
    and 60 of the words not understood."""
    ws = [w for w in words(phrase) if w not in DETERMINERS]
    mentions = find_mentions(ws, all_objects=True)
    where = f"in {bounded(clause, 80)}"
    phrase_q = bounded(phrase, 60)
    if not mentions:
        raise PlanningError(f"unknown object {phrase_q} {where}; known objects: {known_objects()}")
    if len(mentions) > 1:
        raise PlanningError(
            f"{phrase_q} {where} names {len(mentions)} objects "
            f"({listed([m.label() for m in mentions])}); an explicit step names one object and one "
            "target: say 'put the cup on the coaster, then put the bread in the basket'")
    m = mentions[0]
    if m.plural:
        raise PlanningError(
            f"{phrase_q} {where} names several {m.noun}; a step moves one object: name each, "
            f"e.g. 'put the red block on the plate, then put the blue block on the plate'")
    used = set(range(m.first, m.end)) | {k for k, w in enumerate(ws) if w in OTHER}
    extra = [w for k, w in enumerate(ws) if k not in used]
    if extra:
        raise PlanningError(
            f"cannot read {phrase_q} {where} as one object: {bounded(' '.join(extra), 60)} is not "
            f"understood (an object is named as '[size] [colour] type', e.g. 'the small blue bowl'; "
            f"counts, places and conditions are not supported)")
    if len(m.colours) > 1:
        raise PlanningError(f"{phrase_q} {where} gives {len(m.colours)} colours; name one")
    return ObjectRef(type=m.type, accepts=m.accepts, colour=m.colours[0] if m.colours else None,
                     size=m.size, sized=m.sized, other=any(w in OTHER for w in ws), text=phrase)


def uncovered(text: str, objects: Iterable[PlanObject]) -> list[str]:
    """The catalog objects ``text`` names that none of ``objects`` is (by type and colour): a plan
    missing one would carry ``text`` as the label of something else."""
    objects = tuple(objects)
    return [m.label() for m in find_mentions(words(text))
            if not any(m.covered_by(o.type, o.color) for o in objects)]

