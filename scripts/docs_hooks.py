"""MkDocs hooks (mkdocs.yml names this file): pages written from the code and the data at build time.

- ``reference/cli.md``: every ``vcage`` command, its usage, arguments and options, read from the
  command line itself (Typer's commands), so the reference cannot drift from ``--help``.
- ``results.md``: the current figure of each benchmark, read from ``docs/results/*.json``, the files
  the benchmarks write (``benchmarks/results.py``), each with its command, commit, date, machine and
  sample.

A page holds a marker (``<!-- cli-reference -->``, ``<!-- results -->``) that the hook replaces.
``tests/docs`` builds the site with warnings as errors and reads the pages these functions write.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

CLI_MARKER = "<!-- cli-reference -->"
RESULTS_MARKER = "<!-- results -->"
RESULTS = Path(__file__).resolve().parents[1] / "docs" / "results"


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|")


def cli_reference() -> str:
    """Markdown for every command of ``vcage`` in the order ``vcage --help`` lists them."""
    import typer
    from typer._click.core import Context

    from vcage.cli import app

    root = typer.main.get_command(app)
    out: list[str] = []

    def command(cmd: Any, path: list[str]) -> None:
        subs = getattr(cmd, "commands", None)
        if subs:
            if len(path) > 1:
                out.extend([f"## {' '.join(path)}", "", _cell(cmd.help or ""), ""])
            for name, sub in subs.items():
                if not sub.hidden:
                    command(sub, [*path, name])
            return
        ctx = Context(cmd, info_name=path[-1])
        usage = " ".join([*path, *cmd.collect_usage_pieces(ctx)])
        level = "###" if len(path) > 2 else "##"
        out.extend([f"{level} {' '.join(path)}", "", _cell(cmd.help or ""), "", "```text", usage, "```", ""])
        rows = []
        for p in cmd.params:
            record = p.get_help_record(ctx)
            if p.hidden or record is None:
                continue
            rows.append(f"| `{_cell(record[0])}` | {p.param_type_name} | {_cell(record[1])} |")
        if rows:
            out.extend(["| name | kind | what (default) |", "|---|---|---|", *rows, ""])

    command(root, ["vcage"])
    return "\n".join(out)


def load_results(folder: Path = RESULTS) -> list[dict[str, Any]]:
    """Every ``<name>.json`` result in ``folder`` (not its sub-folders, which are ledgers), by name."""
    out = []
    for path in sorted(folder.glob("*.json")):
        data = json.loads(path.read_text())
        data.setdefault("name", path.stem)
        out.append(data)
    return out


def results_page(folder: Path = RESULTS) -> str:
    """Markdown: one section per result, its figures in a table, then where it came from."""
    out: list[str] = []
    for r in load_results(folder):
        out.extend([f"## {r['title']}", "", _cell(r.get("question", "")), ""])
        out.extend(["| figure | value |", "|---|---|"])
        out.extend(f"| {_cell(k)} | {_cell(v)} |" for k, v in r["figures"].items())
        prov = r["provenance"]
        out.extend(["", f"Sample: {_cell(r['sample'])}", "",
                    f"Printed by `{prov['command']}` at commit `{prov['commit']}` on {prov['date']} "
                    f"({_cell(prov['machine'])}); data: `docs/results/{r['name']}.json`."
                    + (f" The commit as run: {_cell(prov['note'])}." if prov.get("note") else ""), ""])
    if not out:
        out.append("No benchmark has written a result yet.")
    return "\n".join(out)


def on_page_markdown(markdown: str, page: Any, **_: Any) -> str:
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference())
    if RESULTS_MARKER in markdown:
        markdown = markdown.replace(RESULTS_MARKER, results_page())
    return markdown
