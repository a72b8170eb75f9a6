"""Does a change leave the data alone? Generate the same datasets with two revisions (or one revision
in two environments) and compare.

Each revision's ``src/`` is exported with ``git archive`` and run through its own command line
(``python -m vcage.cli generate ...``) by the interpreter given for it (default: this one); the
datasets are then compared file by file: every data parquet, episodes parquet, video, states file
and the attempt log must be byte-identical (the extras and meta JSON hold the configuration and the
software's versions, whose shape may change).

    .venv/bin/python benchmarks/same_data.py --before 636fa76 --after HEAD
    .venv/bin/python benchmarks/same_data.py --before HEAD --after HEAD \
        --after-python .venv-latest/bin/python      # the locked versions against the newest (check-latest.sh)

Prints one line per compared file and a summary; exits 1 if any file differs. Under a file that
differs it says where: the fields (as paths, list positions as ``[]``) of the attempt log's lines, the
columns of a parquet table, that differ.
"""

from __future__ import annotations

import argparse
import filecmp
import json
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# (name, arguments of `vcage generate`): both revisions must accept them
RUNS = (
    ("vcage", ["get ready for work", "--episodes", "2", "--seed", "0"]),
    ("vanilla", ["get ready for work", "--episodes", "2", "--seed", "0", "--mode", "vanilla"]),
    ("oracle", ["put the mouse on the mouse pad, then press the bell", "--episodes", "1",
                "--seed", "3", "--critic", "oracle"]),
)
COMPARED = ("*.parquet", "*.mp4", "*.npz", "vcage_attempts.jsonl")


def export(rev: str, into: Path) -> Path:
    """``src/`` of revision ``rev`` under ``into``."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "src"], check=True,
                             capture_output=True).stdout
    tar = into / "src.tar"
    tar.write_bytes(archive)
    with tarfile.open(tar) as t:
        t.extractall(into, filter="data")
    return into / "src"


def generate(src: Path, out: Path, python: str = sys.executable) -> None:
    env = {**os.environ, "PYTHONPATH": str(src)}
    for name, args in RUNS:
        done = subprocess.run([python, "-m", "vcage.cli", "generate", *args, "--out",
                               str(out / name)], env=env, capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"{src}: generate {name} failed:\n{done.stdout}\n{done.stderr}")


def compare(a: Path, b: Path) -> tuple[int, int]:
    """(files compared, files that differ or are missing on one side)."""
    compared = differ = 0
    for name, _ in RUNS:
        files = sorted({p.relative_to(a / name) for pattern in COMPARED for p in (a / name).rglob(pattern)})
        other = sorted({p.relative_to(b / name) for pattern in COMPARED for p in (b / name).rglob(pattern)})
        if files != other:
            print(f"{name}: different files: {sorted(set(files) ^ set(other))}")
            differ += 1
        for rel in files:
            same = (b / name / rel).is_file() and filecmp.cmp(a / name / rel, b / name / rel, shallow=False)
            print(f"{'same' if same else 'DIFF'} {name}/{rel}")
            if not same and (b / name / rel).is_file():
                print(f"    {explain(a / name / rel, b / name / rel)}")
            compared += 1
            differ += not same
    return compared, differ


def explain(a: Path, b: Path) -> str:
    """Where two versions of a file differ: fields of JSON lines, columns of a parquet table."""
    if a.suffix == ".jsonl":
        lines_a, lines_b = a.read_text().splitlines(), b.read_text().splitlines()
        if len(lines_a) != len(lines_b):
            return f"{len(lines_a)} lines against {len(lines_b)}"
        paths: set[str] = set()
        for x, y in zip(lines_a, lines_b, strict=True):
            paths |= _differing(json.loads(x), json.loads(y), "")
        return "fields differ: " + ", ".join(sorted(paths))
    if a.suffix == ".parquet":
        import pyarrow.parquet as pq

        ta, tb = pq.read_table(a), pq.read_table(b)
        if ta.schema != tb.schema or ta.num_rows != tb.num_rows:
            return (f"tables differ in shape: {ta.schema.names} x {ta.num_rows} against "
                    f"{tb.schema.names} x {tb.num_rows}")
        columns = [c for c in ta.schema.names if not ta.column(c).equals(tb.column(c))]
        return "columns differ: " + ", ".join(columns) if columns else "same values, different bytes"
    return "bytes differ"


def _differing(x: object, y: object, path: str) -> set[str]:
    if isinstance(x, dict) and isinstance(y, dict):
        out: set[str] = set()
        for key in set(x) | set(y):
            out |= _differing(x.get(key), y.get(key), f"{path}.{key}" if path else str(key))
        return out
    if isinstance(x, list) and isinstance(y, list) and len(x) == len(y):
        return set().union(*(_differing(i, j, f"{path}[]") for i, j in zip(x, y, strict=True)))
    return set() if x == y else {path}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--before", required=True, help="git revision of the reference")
    parser.add_argument("--after", default="HEAD", help="git revision to check (default HEAD)")
    parser.add_argument("--before-python", default=sys.executable, help="interpreter of the reference")
    parser.add_argument("--after-python", default=sys.executable, help="interpreter of the one checked")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="vcage-same-data-") as tmp:
        root = Path(tmp)
        outs = []
        for label, rev, python in (("before", args.before, args.before_python),
                                   ("after", args.after, args.after_python)):
            (root / label).mkdir()
            generate(export(rev, root / label), root / label / "out", python)
            outs.append(root / label / "out")
        compared, differ = compare(*outs)
    verdict = "all identical" if not differ else f"{differ} differ"
    print(f"{compared} files compared, {verdict}: {args.before} ({args.before_python}) vs {args.after} "
          f"({args.after_python}) "
          f"(runs: {', '.join(name for name, _ in RUNS)})")
    raise SystemExit(1 if differ else 0)


if __name__ == "__main__":
    main()
