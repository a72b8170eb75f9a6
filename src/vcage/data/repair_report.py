"""What a repair did: :class:`RepairReport`, the episodes it kept, dropped, renumbered and rendered
again, the files it rewrote and set aside, and its summary."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from vcage.data.verify_report import VerifyReport, span


@dataclass(frozen=True)
class RepairReport:
    """What :func:`repair` did. ``kept``: the episodes the dataset holds now (0..kept-1)."""

    root: Path
    before: VerifyReport
    after: VerifyReport
    kept: int
    dropped: tuple[int, ...] = ()
    healthy_dropped: tuple[int, ...] = ()  # dropped only because an earlier episode is damaged
    rewritten: tuple[str, ...] = ()  # metadata files rewritten
    removed: tuple[str, ...] = ()  # files deleted
    reasons: dict[int, list[str]] = field(default_factory=dict)  # dropped damaged episode -> its problems
    rebuilt: tuple[int, ...] = ()  # kept episodes whose lost metadata row was rebuilt from their files
    restored: tuple[str, ...] = ()  # files an interrupted write had replaced, given their committed bytes
    quarantine: str | None = None  # where what was removed or cut was set aside (relative to root)
    renumbered: dict[int, int] = field(default_factory=dict)  # kept episode's old index -> new index
    rerendered: tuple[int, ...] = ()  # kept after their videos were rendered again from their states
    resumed: bool = False  # an interrupted repair was carried through first
    compacted: bool = False  # the intact episodes were kept, renumbered (:mod:`.compact`)

    @property
    def changed(self) -> bool:
        return bool(self.rewritten or self.removed or self.restored or self.resumed)

    def summary(self) -> str:
        if not self.changed:
            return f"{self.root}: nothing to repair; {self.kept} episodes verified"
        kept = span(0, self.kept - 1) if self.kept else "no episode"
        lines = [f"{self.root}: kept {kept}"]
        if self.resumed:
            lines.insert(0, f"{self.root}: carried an interrupted repair through")
        if self.dropped and (self.renumbered or not self.healthy_dropped):
            lines[-1] += f", dropped {len(self.dropped)} damaged ({_list(self.dropped)})"
        elif self.dropped:
            lines[-1] += (f", dropped {len(self.dropped)} ({span(self.dropped[0], self.dropped[-1])}), "
                          f"{len(self.healthy_dropped)} of them healthy but after a damaged one")
        if self.dropped:
            for i in sorted(self.reasons):
                lines += [f"  dropped episode {i}: {why}" for why in self.reasons[i]]
        if self.renumbered:
            moves = sorted(self.renumbered.items())
            lines.append(f"  renumbered {len(moves)} intact episodes ({moves[0][0]} is now {moves[0][1]}"
                         + (f", ..., {moves[-1][0]} is now {moves[-1][1]}" if len(moves) > 1 else "")
                         + "); their content is unchanged")
        if self.rerendered:
            lines.append(f"  rendered the videos of {_list(self.rerendered)} again from their stored states "
                         "(the encoded frames match those written)")
        if self.rebuilt:
            lines.append(f"  rebuilt the metadata rows of {span(self.rebuilt[0], self.rebuilt[-1])} from "
                         "their files (image statistics from the decoded videos)")
        if self.restored:
            lines.append(f"  put back the committed bytes of {', '.join(self.restored)} (an interrupted "
                         "write had replaced them)")
        if self.rewritten:
            lines.append(f"  rewrote {', '.join(self.rewritten)}")
        if self.quarantine and self.compacted:
            lines.append(f"  set aside the {len(self.removed)} files it dropped or replaced, as they were, "
                         f"in {self.quarantine}/ (NOTE.md there says why; nothing was deleted)")
        elif self.quarantine:
            lines.append(f"  set aside {len(self.removed)} files and the shared files as they were before "
                         f"the cut in {self.quarantine}/ (NOTE.md there says why; nothing was deleted)")
        else:
            lines.append(f"  removed {len(self.removed)} files" if self.removed else "  removed no file")
        lines.append("  verified clean afterwards" if self.after.ok else
                     f"  still damaged afterwards: {self.after.brief()}")
        return "\n".join(lines)


def _list(indices: tuple[int, ...]) -> str:
    more = f" and {len(indices) - 8} more" if len(indices) > 8 else ""
    return ", ".join(str(i) for i in indices[:8]) + more
