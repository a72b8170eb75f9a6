"""What a check of a dataset found: each damage as a :class:`Problem`, all of them as a
:class:`VerifyReport`, which says what a repair would drop."""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from vcage.errors import CorruptDatasetError


@dataclass(frozen=True)
class Problem:
    """One damage: the file (relative to the dataset root), the episodes it costs, what is wrong.

    ``episode`` is None for damage to the dataset's metadata as a whole (no episode is lost by it
    alone); ``last`` is the last episode of a range (``episode``..``last``), else equal to ``episode``.
    """

    path: str
    episode: int | None
    what: str
    last: int | None = None
    interrupted: bool = False  # what an interrupted write left: the next writer (or repair) undoes it

    @property
    def episodes(self) -> range:
        if self.episode is None:
            return range(0)
        return range(self.episode, (self.last if self.last is not None else self.episode) + 1)

    @property
    def where(self) -> str:
        if self.episode is None:
            return "metadata"
        return span(self.episode, self.last if self.last is not None else self.episode)

    def __str__(self) -> str:
        return f"{self.path} ({self.where}): {self.what}"


@dataclass(frozen=True)
class VerifyReport:
    """What :func:`verify` or :func:`check` found. ``episodes``: the committed episodes checked."""

    root: Path
    episodes: int
    frames: int
    decoded: bool  # videos fully decoded (verify) or only their container read (check)
    problems: tuple[Problem, ...] = ()
    repairable: bool = True  # False: :func:`repair` refuses (lost info.json without a copy, lost config)
    keeps_intact: bool = False  # a vcage dataset: the repair keeps every intact episode, renumbered

    @property
    def ok(self) -> bool:
        return not self.problems

    def without_interrupted(self) -> VerifyReport:
        """This report without what an interrupted write left (which the next writer undoes)."""
        return replace(self, problems=tuple(p for p in self.problems if not p.interrupted))

    @property
    def damaged(self) -> tuple[int, ...]:
        """Indices of the episodes with a problem of their own, ascending."""
        return tuple(sorted({i for p in self.problems for i in p.episodes}))

    @property
    def first_damaged(self) -> int | None:
        return self.damaged[0] if self.damaged else None

    @property
    def healthy_after_first_damaged(self) -> int:
        """Episodes without a problem that a repair drops because an earlier one is damaged."""
        first = self.first_damaged
        return 0 if first is None else self.episodes - first - len(self.damaged)

    def brief(self, limit: int = 3) -> str:
        """The problems in one line: the first ``limit`` and how many more."""
        if self.ok:
            return "no problems"
        shown = "; ".join(str(p) for p in self.problems[:limit])
        more = len(self.problems) - limit
        return f"{len(self.problems)} problem(s): {shown}" + (f"; and {more} more" if more > 0 else "")

    def summary(self) -> str:
        """Several lines: what was checked, every problem, and what ``--repair`` would drop."""
        how = "videos decoded" if self.decoded else "cheap checks: videos not decoded"
        head = f"{self.root}: {self.episodes} episodes, {self.frames} frames checked ({how})"
        if self.ok:
            return head + "; no problems"
        lines = [head + f"; {len(self.problems)} problem(s):", *(f"  {p}" for p in self.problems)]
        first = self.first_damaged
        if not self.repairable:
            lines.append("`vcage verify --repair` cannot fix this: the metadata it needs is lost; restore "
                         "the damaged metadata files from a copy")
        elif any(p.path.startswith("meta/episodes") and p.episode is not None for p in self.problems):
            lines.append("`vcage verify --repair` rebuilds the lost metadata rows from the episodes' files "
                         "where it can, then drops the episodes from the first damaged one on")
        elif first is None:
            lines.append("no episode is lost; `vcage verify --repair` rewrites the metadata")
        elif self.keeps_intact:
            intact = self.episodes - len(self.damaged)
            lines.append(f"`vcage verify --repair` drops the {len(self.damaged)} damaged episode(s), unless "
                         "their videos alone are damaged and render again from their stored states, and "
                         + (f"keeps the {intact} intact one(s), renumbered" if intact else "keeps no other"))
        else:
            keeps = f"keeps {span(0, first - 1)} and drops" if first else "drops every episode:"
            lines.append(f"`vcage verify --repair` {keeps} {span(first, self.episodes - 1)} "
                         f"({self.healthy_after_first_damaged} of them healthy)")
        return "\n".join(lines)

    def raise_if_damaged(self) -> None:
        """CorruptDatasetError naming the damage and the repair, unless the report is clean of all but
        what an interrupted write left (vcage's readers read the committed bytes; a plain reader of
        the files would not, which ``vcage verify`` reports)."""
        if not self.without_interrupted().ok:
            raise CorruptDatasetError(f"{self.root} is damaged: {self.brief()}; run `vcage verify "
                                      f"{self.root} --repair` to drop the damaged episodes")


def span(first: int, last: int) -> str:
    return f"episode {first}" if first == last else f"episodes {first}-{last}"
