"""The catalog is an ordinary registry, filled by importing the package, with no import cycle."""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

import vcage.assets
from vcage.assets.catalog import CATALOG
from vcage.errors import CatalogError
from vcage.registry import Registry

ASSETS = Path(vcage.assets.__file__).parent
OBJECTS = "vcage.assets.objects"


def test_catalog_is_a_registry_raising_catalog_errors() -> None:
    assert isinstance(CATALOG, Registry)
    assert CATALOG.values() == [CATALOG.get(n) for n in CATALOG.names()]
    assert list(CATALOG) == CATALOG.names() == sorted(CATALOG.names())
    with pytest.raises(CatalogError, match="already registered"):
        CATALOG.add_type(CATALOG.get("cup"))
    with pytest.raises(CatalogError, match="valid names: alarm_clock, apple"):
        CATALOG.get("dragon")


def test_importing_the_catalog_module_alone_gives_the_full_catalog() -> None:
    code = ("import json, sys; from vcage.assets.catalog import CATALOG; "
            "json.dump([CATALOG.names(), CATALOG.categories()], sys.stdout)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    names, categories = json.loads(run.stdout)
    assert names == CATALOG.names() and len(names) == len(CATALOG) >= 30
    assert categories == CATALOG.categories()


def _module_name(path: Path) -> str:
    parts = path.relative_to(ASSETS.parent.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every module ``path`` imports (relative imports resolved; ``from a import b`` gives a.b too)."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")
            if node.level:
                base = base[: len(base) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            found.add(source)
            found.update(f"{source}.{alias.name}" for alias in node.names)
    return found


def test_only_package_inits_import_the_objects_package() -> None:
    """``catalog`` must not import the objects that import it: registration runs from the package
    ``__init__`` files, so no module under ``vcage.assets`` imports ``vcage.assets.objects``."""
    files = sorted(ASSETS.rglob("*.py"))
    assert {p.name for p in files} >= {"catalog.py", "__init__.py", "kitchen.py"}
    offenders = {
        _module_name(p): sorted(i for i in _imports(p) if i == OBJECTS or i.startswith(OBJECTS + "."))
        for p in files if p.name != "__init__.py"
    }
    assert {m: i for m, i in offenders.items() if i} == {}
    # ... and the package does import it, so importing any assets module fills the catalog.
    assert OBJECTS in _imports(ASSETS / "__init__.py")
