"""A repair that keeps the intact episodes rewrites many files; a crash at any point of it loses
nothing: before its plan is complete the dataset is as it was, after it the next repair (or any
writer, which refuses until then) carries it through."""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from data.content import contents_by_episode
from data.test_integrity import episode_files, open_writer, truncate, write_dataset
from vcage.data import DatasetReader, compact, layout, video
from vcage.data.repair import repair
from vcage.data.verify import verify
from vcage.errors import CorruptDatasetError


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_dataset(tmp_path_factory.mktemp("repair-crash") / "ds")


class CrashError(Exception):
    pass


class Replace:
    """``os.replace`` (every atomic write and every move of the repair goes through it) that counts
    its calls and crashes at call ``crash_at``."""

    def __init__(self, real: Callable[[Any, Any], None], crash_at: int | None = None) -> None:
        self.real, self.crash_at, self.calls = real, crash_at, 0

    def __call__(self, src: Any, dst: Any) -> None:
        if self.calls == self.crash_at:
            raise CrashError
        self.calls += 1
        self.real(src, dst)


def test_a_crash_at_every_file_operation_of_a_repair_loses_nothing(
        pristine: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Before the plan is written the dataset is as it was (the next repair starts again); after it,
    the dataset is refused by every writer and the next repair carries the plan through. Either way
    the intact episodes come out unchanged."""
    expected = contents_by_episode(pristine)
    expected = [expected[0], expected[2], expected[3]]
    real = compact.os.replace
    counting = Replace(real)
    copy = tmp_path / "count"
    shutil.copytree(pristine, copy)
    truncate(copy / episode_files(1)[0])
    monkeypatch.setattr(compact.os, "replace", counting)
    repair(copy)
    monkeypatch.setattr(compact.os, "replace", real)
    assert counting.calls > 20
    planned = 0
    for crash_at in range(counting.calls):
        root = tmp_path / f"ds{crash_at}"
        shutil.copytree(pristine, root)
        truncate(root / episode_files(1)[0])
        monkeypatch.setattr(compact.os, "replace", Replace(real, crash_at))
        with pytest.raises(CrashError):
            repair(root)
        monkeypatch.setattr(compact.os, "replace", real)
        report = verify(root)
        had_plan = (root / layout.REPAIR_PLAN).exists()
        if had_plan:
            planned += 1
            assert any(p.path == layout.REPAIR_PLAN for p in report.problems), crash_at
            with pytest.raises(CorruptDatasetError, match="verify .* --repair"):
                open_writer(root)
        else:
            assert report.damaged == (1,) and len(DatasetReader(root, videos=False)) == 4, crash_at
        result = repair(root)
        assert result.resumed == had_plan and result.after.ok, crash_at
        assert contents_by_episode(root) == expected, crash_at
        assert not (root / layout.REPAIR_STAGING).exists()
        assert episode_files(1)[0] in "".join(n.read_text() for n in root.glob("quarantine/*/NOTE.md"))
        shutil.rmtree(root)
    assert planned > 10  # crashes after the plan, while it is carried through, were tried


def test_a_crash_while_staging_leaves_the_dataset_as_it_was(pristine: Path, tmp_path: Path,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    root = tmp_path / "ds"
    shutil.copytree(pristine, root)
    expected = contents_by_episode(root)
    truncate(root / episode_files(1)[0])
    before = {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}

    def crash(*args: object, **kw: object) -> None:
        raise CrashError

    monkeypatch.setattr(video, "concat_videos", crash)
    with pytest.raises(CrashError):
        repair(root)
    monkeypatch.undo()
    after = {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}
    assert {p: b for p, b in after.items() if layout.REPAIR_STAGING not in str(p)} == before
    assert verify(root).damaged == (1,)  # the half-built staging is not a repair to carry through
    result = repair(root)
    assert not result.resumed and result.after.ok and not (root / layout.REPAIR_STAGING).exists()
    assert contents_by_episode(root) == [expected[0], expected[2], expected[3]]
