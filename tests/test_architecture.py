"""What import contracts cannot check: dynamic code execution stays out of the package.

``exec``/``eval``/``compile`` of text belong to one sandbox module: the child process that runs
generated subtask code (``sandbox/child.py``, started as its own interpreter, never imported); no
other module may call them. Import contracts (``lint-imports``, configured in pyproject.toml) check
the layers.
"""

from __future__ import annotations

import ast
from pathlib import Path

import vcage

SANDBOX = {"sandbox/child.py"}  # modules allowed to execute text as code (relative to src/vcage)
DANGEROUS = {"exec", "eval", "compile", "__import__"}


def _calls(path: Path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(), str(path))
    return [(node.lineno, node.func.id) for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in DANGEROUS]


def test_no_module_outside_the_sandbox_executes_text_as_code() -> None:
    root = Path(vcage.__file__).parent
    found = {str(p.relative_to(root)): calls for p in sorted(root.rglob("*.py"))
             if (calls := _calls(p)) and str(p.relative_to(root)) not in SANDBOX}
    assert found == {}


def test_the_sandbox_module_is_the_one_that_executes_and_nothing_imports_it() -> None:
    root = Path(vcage.__file__).parent
    assert {name for name in SANDBOX if _calls(root / name)} == SANDBOX  # the exception is used
    importers = [str(p.relative_to(root)) for p in sorted(root.rglob("*.py")) if _imports_child(p)]
    assert importers == []  # the runner starts it as a script by path


def _imports_child(path: Path) -> bool:
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import) and any(a.name.endswith("sandbox.child") for a in node.names):
            return True
        if isinstance(node, ast.ImportFrom) and (
                (node.module or "").endswith("sandbox.child")
                or ((node.module or "").endswith("sandbox") and any(a.name == "child" for a in node.names))):
            return True
    return False


def test_the_scan_sees_a_call(tmp_path: Path) -> None:
    probe = tmp_path / "probe.py"
    probe.write_text("x = eval('1 + 1')\n")
    assert _calls(probe) == [(1, "eval")]


def test_plans_and_critics_load_no_simulator() -> None:
    """The plan schema, planners and critics read the catalog's metadata, never MuJoCo or mink."""
    import subprocess
    import sys

    code = ("import sys; from vcage.planning import make_planner; import vcage.critics; "
            "make_planner('offline').plan('get ready for work'); "
            "heavy = ('mujoco', 'mink', 'vcage.sim.world', 'vcage.tasks'); "
            "print(sorted(m for m in heavy if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


MODULE_LINES = 400  # a module past this holds more than one concept: split it (docs/ARCHITECTURE.md)


def test_no_module_is_longer_than_the_limit() -> None:
    root = Path(vcage.__file__).parent
    long = {str(p.relative_to(root)): n for p in sorted(root.rglob("*.py"))
            if (n := len(p.read_text().splitlines())) > MODULE_LINES}
    assert not long, f"modules over {MODULE_LINES} lines: {long}"
