"""The lock file pins everything the project declares, within its ranges, with hashes; and the
environment the tests run in is the locked one (scripts/setup.sh installs from it)."""

from __future__ import annotations

import re
import tomllib
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

TOP = Path(__file__).resolve().parents[1]
LOCK = TOP / "requirements" / "lock.txt"


def _pins() -> dict[str, tuple[str, list[str]]]:
    """``{name: (version, hashes)}`` of the lock file."""
    out: dict[str, tuple[str, list[str]]] = {}
    for block in re.split(r"\n(?=[A-Za-z0-9])", LOCK.read_text()):
        head = re.match(r"([A-Za-z0-9_.\-]+)==(\S+)", block)
        if head:
            out[canonicalize_name(head[1])] = (head[2], re.findall(r"--hash=sha256:([0-9a-f]{64})", block))
    return out


def _declared() -> list[Requirement]:
    project = tomllib.loads((TOP / "pyproject.toml").read_text())["project"]
    extras = project.get("optional-dependencies", {})
    return [Requirement(r) for r in [*project["dependencies"], *(r for rs in extras.values() for r in rs)]]


def test_every_declared_requirement_is_pinned_within_its_range_with_hashes() -> None:
    pins = _pins()
    assert pins and all(hashes for _, hashes in pins.values()), "a pin without hashes"
    for req in _declared():
        name = canonicalize_name(req.name)
        assert name in pins, f"{req} is declared but not locked: run bash scripts/lock.sh"
        assert req.specifier.contains(Version(pins[name][0]), prereleases=True), \
            f"{name}=={pins[name][0]} is outside {req}: run bash scripts/lock.sh"


def test_the_environment_is_the_locked_one() -> None:
    """Every locked package is installed at its locked version (scripts/check-latest.sh's environment,
    built from the ranges instead, fails here and says what moved)."""
    moved = []
    for name, (pinned, _) in _pins().items():
        try:
            installed = version(name)
        except PackageNotFoundError:
            moved.append(f"{name}: {pinned} locked, not installed")
            continue
        if Version(installed) != Version(pinned):
            moved.append(f"{name}: {pinned} locked, {installed} installed")
    assert not moved, moved
