"""The files one episode's write creates, replaces (keeping backups) and uses as scratch, so that
the episode can be committed or undone."""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from pathlib import Path

from vcage.data.files import atomic_write, keep_backup, restore_backup


class _EpisodeFiles:
    """The files one episode's write created, replaced (with their backups) and used as scratch."""

    def __init__(self) -> None:
        self.created: list[Path] = []
        self.backups: list[tuple[Path, Path]] = []  # (file, its bytes before the episode)
        self.scratches: list[Path] = []

    def scratch(self, path: Path) -> Path:
        self.scratches.append(path)
        return path

    def create(self, path: Path, write: Callable[[Path], object]) -> None:
        self.created.append(path)
        atomic_write(path, write)

    def replace(self, path: Path, committed: int, write: Callable[[Path], object]) -> None:
        """Rewrite ``path`` (which holds ``committed`` episodes' content) after keeping a backup."""
        self.backups.append((path, keep_backup(path, committed)))
        atomic_write(path, write)

    def remove_scratch(self) -> None:
        for path in self.scratches:
            path.unlink(missing_ok=True)

    def forget_backups(self) -> None:
        """The episode committed: the backups are no longer needed."""
        for _, backup in self.backups:
            with contextlib.suppress(OSError):
                backup.unlink(missing_ok=True)

    def undo(self) -> None:
        """The episode did not commit: back to the files as they were (best effort)."""
        self.remove_scratch()
        for path in self.created:
            with contextlib.suppress(OSError):
                path.unlink(missing_ok=True)
        for path, backup in self.backups:
            with contextlib.suppress(OSError):
                restore_backup(backup, path)
