"""Relation templates: the arrangement an offline description gives objects the prompt leaves free.

Two templates, applied in order: **pairing** rests each graspable object that has no support on a
free host of the scene that fits it and goes with it (a container's inside first, then a surface;
a fruit into a bowl, never a mouse into a mug), and **row** lines
the groups standing on the table up from left to right (``left_of`` and ``aligned`` between
neighbours) when they fit in :data:`ROW_SPAN`.
"""

from __future__ import annotations

from vcage.assets.catalog import CATALOG
from vcage.scene.layout import IN_FILL, ON_OVERHANG
from vcage.synthesis.description import SceneObject, SceneRelation

ROW_SPAN = 0.7  # widest row the template lines up (m): within the arm's reach across the table
ROW_GAP = 0.04
MAX_ROW = 4


def _fits(child: SceneObject, host: SceneObject, kind: str) -> bool:
    places = [p for p in CATALOG.get(host.type).placements if p.kind == kind]
    if not places:
        return False
    ours = sorted(2 * h for h in child.half_extents())
    theirs = sorted(s * host.scale for s in CATALOG.get(host.type).size[:2])
    limit = ON_OVERHANG * 0.6 if kind == "on" else IN_FILL * 0.9
    return ours[0] <= limit * theirs[0] and ours[1] <= limit * theirs[1]


# what kind of place an object belongs to, from its catalog tags and category; a host of a domain
# takes objects of a domain that goes with it (a fruit into a bowl, a mouse onto a mouse pad), a
# host of none (a basket, a box) takes anything, and an object of none goes onto any host
DOMAINS = frozenset({"kitchen", "tableware", "food", "office", "electronics", "toy", "household"})
GOES_WITH = {"food": {"kitchen", "tableware", "food"}, "kitchen": {"kitchen", "tableware", "food"},
             "tableware": {"kitchen", "tableware", "food"}, "office": {"office", "electronics"},
             "electronics": {"office", "electronics"}, "toy": {"toy"}, "household": {"household"}}


def domains(o: SceneObject) -> set[str]:
    t = CATALOG.get(o.type)
    return (set(t.tags) | {t.category}) & DOMAINS


def goes_with(child: SceneObject, host: SceneObject) -> bool:
    mine, theirs = domains(child), domains(host)
    return not mine or not theirs or any(theirs & GOES_WITH[d] for d in mine)


def pairing(objects: tuple[SceneObject, ...], relations: list[SceneRelation]) -> list[SceneRelation]:
    """Support relations for graspable objects without one, one object per host."""
    supported = {r.a for r in relations if r.kind in ("on", "inside")}
    used = {r.b for r in relations if r.kind in ("on", "inside")}
    related = {n for r in relations for n in (r.a, r.b)}
    paired = {frozenset((r.a, r.b)) for r in relations}
    out = []
    for child in objects:
        if child.name in supported or child.name in used or not CATALOG.get(child.type).grasps:
            continue
        if CATALOG.get(child.type).placements and child.name not in related:
            continue  # a free host stays a host
        for kind, word in (("in", "inside"), ("on", "on")):
            host = next((h for h in objects if h.name not in used and h.name != child.name
                         and h.name not in supported and frozenset((child.name, h.name)) not in paired
                         and _fits(child, h, kind) and goes_with(child, h)), None)
            if host is not None:
                out.append(SceneRelation(kind=word, a=child.name, b=host.name))  # type: ignore[arg-type]
                used.add(host.name)
                supported.add(child.name)
                break
    return out


def row(objects: tuple[SceneObject, ...], relations: list[SceneRelation]) -> list[SceneRelation]:
    """``left_of`` and ``aligned`` between neighbouring table groups, if they fit in a row and the
    description orders none of them already."""
    supported = {r.a for r in relations if r.kind in ("on", "inside")}
    ordered = {n for r in relations if r.kind not in ("on", "inside") for n in (r.a, r.b)}
    groups = [o for o in objects if o.name not in supported]
    if len(groups) < 2 or len(groups) > MAX_ROW or ordered & {g.name for g in groups}:
        return []
    width = sum(2 * g.radius for g in groups) + ROW_GAP * (len(groups) - 1)
    if width > ROW_SPAN:
        return []
    out = []
    for a, b in zip(groups, groups[1:], strict=False):
        out.append(SceneRelation(kind="left_of", a=a.name, b=b.name, distance=ROW_GAP))
        out.append(SceneRelation(kind="aligned", a=a.name, b=b.name))
    return out


def sentence(rel: SceneRelation, objects: dict[str, SceneObject]) -> str:
    words = {"on": "on", "inside": "inside", "left_of": "to the left of", "right_of": "to the right of",
             "in_front_of": "in front of", "behind": "behind", "near": "next to",
             "aligned": "in one row with"}
    a, b = objects[rel.a], objects[rel.b]
    return f"the {_label(a)} {words[rel.kind]} the {_label(b)}"


def _label(o: SceneObject) -> str:
    return " ".join(filter(None, (o.color, o.type.replace("_", " "))))


def image_text(objects: tuple[SceneObject, ...], relations: list[SceneRelation]) -> str:
    """The instruction an image-editing model gets with the initial top-down image."""
    by = {o.name: o for o in objects}
    wanted = "; ".join(sentence(r, by) for r in relations) or "a tidy arrangement with space between them"
    return ("Top-down orthographic photo of a robot's work table. Move the objects, keeping each one's "
            f"exact look and size, adding and removing nothing, so that: {wanted}. The robot stands at the "
            "bottom of the image; its left is the image's left.")
