"""A benchmark's current figure as data: ``docs/results/<name>.json``, written by the benchmark itself.

Each file holds the question the benchmark answers, its figures (label -> value as printed), the
sample they rest on (how many successes and failures, scenes, seeds) and where they came from: the
command line, the commit (with ``+dirty`` when the package differs from it), the date and the
machine. The documentation's results page (``docs/results.md``, built by ``scripts/docs_hooks.py``)
is made from these files, so a figure on it always names its command and commit. A benchmark
writes its file only when asked (``--record``), so a trial run leaves the published figure alone.
"""

from __future__ import annotations

import contextlib
import datetime
import json
import os
import platform
import shlex
import sys
from pathlib import Path
from typing import Any

from vcage.provenance import code

RESULTS = Path(__file__).resolve().parents[1] / "docs" / "results"


def machine() -> str:
    """Cores, memory, CPU model and Python: enough to tell one machine's figure from another's."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
        mem = int(next(ln.split()[1] for ln in Path("/proc/meminfo").read_text().splitlines()
                       if ln.startswith("MemTotal"))) / 2**20
    except (OSError, StopIteration, ValueError):
        mem = float("nan")
    return f"{os.cpu_count()} cores, {mem:.0f} GiB, {cpu}, Python {platform.python_version()}"


def command_line() -> str:
    """The command that ran, as one would type it again from the repository's root."""
    script = Path(sys.argv[0])
    with contextlib.suppress(ValueError):  # a script outside the checkout keeps its own path
        script = script.resolve().relative_to(Path(__file__).resolve().parents[1])
    threads = f"LP_NUM_THREADS={os.environ['LP_NUM_THREADS']} " if "LP_NUM_THREADS" in os.environ else ""
    return f"{threads}.venv/bin/python {shlex.join([str(script), *sys.argv[1:]])}"


def record(name: str, title: str, question: str, figures: dict[str, Any], sample: str,
           folder: Path = RESULTS, made: dict[str, str] | None = None) -> Path:
    """Write ``folder/<name>.json`` (replacing the figure it held) and return its path.

    ``made`` replaces provenance fields where this process only reports figures another run made
    (a ledger assembled over sessions): its ``commit`` (a full hash, ``+patched`` with a ``note``
    saying what was applied) and ``date`` are then that run's, and the machine is not recorded
    unless given."""
    provenance = {"command": command_line(), "commit": code()["commit"],
                  "date": datetime.date.today().isoformat(), "machine": machine()}
    if made is not None:
        provenance = {"command": provenance["command"], "machine": "not recorded by the run"} | made
    data = {"name": name, "title": title, "question": question,
            "figures": {str(k): v for k, v in figures.items()}, "sample": sample, "provenance": provenance}
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(data, indent=2) + "\n")
    tmp.replace(path)
    return path
