"""Where a repair sets aside what it takes out of a dataset (nothing is deleted): ``quarantine/<time>/``
for files, and a ``.damaged-<time>`` file beside a vcage log for its lines that are not JSON."""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

from vcage.data import layout
from vcage.data.files import write_text
from vcage.data.scan import bad_log_lines
from vcage.data.verify_report import VerifyReport, span

QUARANTINE = "quarantine"  # inside the dataset; LeRobot and vcage's readers never look there


class Quarantine:
    """Where a repair sets aside what it removes from the dataset or cuts out of a shared file:
    ``quarantine/<time>/`` inside it, the files under their own paths, and ``NOTE.md`` saying why.
    Created on first use; nothing is deleted."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.dir: Path | None = None
        self.entries: list[str] = []

    def folder(self) -> str:
        """The folder (relative to the dataset) this repair sets aside into; chosen on first call."""
        if self.dir is None:
            stamp = time.strftime("%Y%m%d-%H%M%S")
            base = self.root / QUARANTINE / stamp
            k = 1
            while base.exists():
                k += 1
                base = self.root / QUARANTINE / f"{stamp}-{k}"
            self.dir = base
        return self.dir.relative_to(self.root).as_posix()

    def _target(self, rel: str) -> Path:
        out = self.root / self.folder() / rel
        out.parent.mkdir(parents=True, exist_ok=True)
        return out

    def copy(self, rel: str) -> None:
        """Keep the file at ``rel`` as it is now (before a repair cuts it)."""
        if (self.root / rel).is_file():
            shutil.copyfile(self.root / rel, self._target(rel))
            self.entries.append(f"{rel}: as it was before the repair cut it")

    def move(self, rel: str) -> None:
        os.replace(self.root / rel, self._target(rel))
        self.entries.append(f"{rel}: removed from the dataset")

    def note(self, found: VerifyReport, kept: int, dropped: tuple[int, ...]) -> str | None:
        """Write ``NOTE.md``; the folder relative to the dataset, or None where nothing was set aside."""
        if self.dir is None:
            return None
        lines = [f"# Set aside by `vcage verify --repair` on {time.strftime('%Y-%m-%d %H:%M:%S')}", "",
                 f"The dataset kept {span(0, kept - 1) if kept else 'no episode'}"
                 + (f" and dropped {span(dropped[0], dropped[-1])}." if dropped else "."), "",
                 "What verify found:", "", *(f"- {p}" for p in found.problems), "", "Files here:", "",
                 *(f"- {e}" for e in self.entries), ""]
        (self.dir / "NOTE.md").write_text("\n".join(lines))
        return self.dir.relative_to(self.root).as_posix()


def _set_aside_bad_lines(root: Path) -> list[str]:
    """Rewrite each vcage log without the lines that are not JSON, which go to a ``.damaged-<time>``
    file beside it (nothing is deleted); the logs rewritten."""
    out = []
    for rel in (layout.ATTEMPTS_LOG, layout.RUNS_LOG):
        path = root / rel
        bad = set(bad_log_lines(path))
        if not bad:
            continue
        lines = path.read_text(errors="replace").splitlines(keepends=True)
        stamp = time.strftime("%Y%m%d-%H%M%S")
        write_text(path.with_name(f"{path.name}.damaged-{stamp}"), "".join(lines[i] for i in sorted(bad)))
        write_text(path, "".join(line for i, line in enumerate(lines) if i not in bad))
        out.append(rel)
    return out
