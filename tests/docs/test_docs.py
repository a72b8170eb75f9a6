"""The documentation cannot rot: the site builds with warnings as errors (and a broken link fails it),
the command-line reference is read from the commands themselves, every figure on the results page
names its command and commit, and every ``vcage`` command line in the README's and the guides'
shell blocks parses against the real command line (options that exist, values of the right type),
and the architecture's diagram of the packages and their imports is the code's.
The README's "make your own dataset" block runs for real, at smaller sizes (slow)."""

from __future__ import annotations

import json
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import docs_hooks  # noqa: E402, I001 - from scripts/ and benchmarks/, put on the path above
import package_diagram  # noqa: E402
import results  # noqa: E402

MKDOCS = Path(sys.executable).parent / "mkdocs"
# what the docs say now (the journal, docs/journal/, keeps each command as it ran then)
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
        *sorted((ROOT / "docs" / "guides").glob("*.md"))]


def build(config: Path, site: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    return subprocess.run([str(MKDOCS), "build", "--strict", "-f", str(config), "-d", str(site)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300, check=False, env=env)


def test_the_site_builds_with_warnings_as_errors_and_a_broken_link_fails_it(tmp_path: Path) -> None:
    done = build(ROOT / "mkdocs.yml", tmp_path / "site")
    assert done.returncode == 0, done.stderr
    cli = (tmp_path / "site" / "reference" / "cli" / "index.html").read_text()
    assert 'id="vcage-generate"' in cli and "--max-attempts" in cli
    assert (tmp_path / "site" / "reference" / "api" / "index.html").read_text().count("doc-heading") > 10
    # the same site with one link to a page that does not exist
    docs = tmp_path / "docs"
    shutil.copytree(ROOT / "docs", docs)
    (docs / "concepts.md").write_text((docs / "concepts.md").read_text() + "\n[gone](no-such-page.md)\n")
    config = tmp_path / "mkdocs.yml"
    hooks = ROOT / "scripts" / "docs_hooks.py"
    config.write_text(f"INHERIT: {ROOT / 'mkdocs.yml'}\ndocs_dir: {docs}\nhooks: [{hooks}]\n")
    broken = build(config, tmp_path / "broken")
    assert broken.returncode != 0 and "no-such-page.md" in broken.stderr


def _commands() -> dict[str, Any]:
    import typer

    from vcage.cli import app

    out: dict[str, Any] = {}

    def walk(cmd: Any, path: tuple[str, ...]) -> None:
        subs = getattr(cmd, "commands", None)
        if subs:
            for name, sub in subs.items():
                walk(sub, (*path, name))
        else:
            out[" ".join(path)] = cmd

    walk(typer.main.get_command(app), ())
    return out


def test_the_cli_reference_names_every_command_and_every_option() -> None:
    page = docs_hooks.cli_reference()
    for name, cmd in _commands().items():
        assert f"## vcage {name}\n" in page, name
        for p in cmd.params:
            for opt in p.opts:
                if opt.startswith("-") and not p.hidden:
                    assert f"`{opt}" in page or f" {opt} " in page or f"{opt}<" in page or opt in page, \
                        (name, opt)


def test_every_result_names_its_command_commit_date_and_sample(tmp_path: Path) -> None:
    path = results.record("demo", "A demo", "Does it work?", {"agreement": "96.8% of 932"},
                          "932 subtasks (671 successes, 261 failures), 312 scenes", folder=tmp_path)
    page = docs_hooks.results_page(tmp_path)
    data = json.loads(path.read_text())
    assert "96.8% of 932" in page and "312 scenes" in page
    assert f"`{data['provenance']['command']}`" in page and data["provenance"]["commit"] in page
    # the command of this process (pytest's, or an xdist worker's ``python -c``), as it was typed
    assert data["provenance"]["command"].endswith(shlex.join([Path(sys.argv[0]).name, *sys.argv[1:]]))
    for stored in docs_hooks.load_results():  # every published result
        prov = stored["provenance"]
        assert stored["figures"] and stored["sample"], stored["name"]
        assert prov["command"].startswith(("LP_NUM_THREADS", ".venv/bin/python benchmarks/")), stored["name"]
        assert re.fullmatch(r"[0-9a-f]{40}(\+dirty|\+patched)?", prov["commit"]), stored["name"]
        assert not prov["commit"].endswith("+patched") or prov.get("note"), stored["name"]  # says what
        assert re.fullmatch(r"\d{4}-\d\d-\d\d", prov["date"]) and prov["machine"], stored["name"]


SYNOPSIS = re.compile(r"[\[\]|…]|\.\.\.")  # "[--episodes N]", "a|b", "...": a synopsis, not a command


def command_lines(path: Path) -> tuple[list[str], list[str]]:
    """The ``vcage ...`` command lines of ``path`` (in ```bash blocks and after ``$ `` in
    transcripts; comments cut, continued lines joined) and its inline mentions of a command with
    options (`` `vcage train --obs-stride K` ``; not synopses with brackets or alternatives)."""
    lines, mentions, block = [], [], None
    for line in path.read_text().replace("\\\n", " ").splitlines():
        if line.startswith("```"):
            block = line.strip()[3:] if block is None else None
            continue
        if block is not None:
            text = line.split(" #")[0].strip()
            if block == "bash" or text.startswith("$ "):
                text = text.removeprefix("$ ").removeprefix(".venv/bin/")
                if text.startswith("vcage "):
                    lines.append(text)
            continue
        mentions += [m for m in re.findall(r"`(vcage [^`]+)`", line) if not SYNOPSIS.search(m)]
    return lines, mentions


def _split(part: str, commands: dict[str, Any]) -> tuple[str | None, list[str]]:
    words = shlex.split(part)[1:]
    name = next((n for n in sorted(commands, key=len, reverse=True) if words[:len(n.split())] == n.split()),
                None)
    return name, words[len(name.split()):] if name else words


def rotted_lines(paths: list[Path]) -> tuple[list[str], int]:
    """Command lines of ``paths`` that do not parse whole (an option that does not exist, a value of
    the wrong type) and inline mentions that name a command or an option that does not exist; and
    how many were checked."""
    commands = _commands()
    rotted, checked = [], 0
    for path in paths:
        where = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path.name
        lines, mentions = command_lines(path)
        for line in lines:
            for part in line.split("&&"):
                name, args = _split(part, commands)
                checked += 1
                if name is None:
                    rotted.append(f"{where}: {part.strip()!r}: no such command")
                    continue
                try:
                    commands[name].make_context(name, args)
                except Exception as exc:  # noqa: BLE001 - any refusal is a line that has rotted
                    if type(exc).__name__ != "Exit":  # --help exits
                        rotted.append(f"{where}: {part.strip()!r}: {exc}")
        for mention in mentions:
            name, args = _split(mention, commands)
            checked += 1
            if name is None:
                rotted.append(f"{where}: {mention!r}: no such command")
                continue
            known = {o for p in commands[name].params for o in (*p.opts, *p.secondary_opts)}
            rotted += [f"{where}: {mention!r}: {a} is no option of vcage {name}" for a in args
                       if a.startswith("--") and a.split("=")[0] not in known]
    return rotted, checked


def test_every_vcage_command_line_of_the_docs_parses() -> None:
    rotted, checked = rotted_lines(DOCS)
    assert checked >= 60, checked  # the README's, getting started's, the guides' and STATUS's
    assert not rotted, "\n".join(rotted)


def test_a_rotted_command_line_or_mention_is_caught(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text("Run `vcage train --stride 2` or `vcage verify DIR --repair`.\n\n```bash\n"
                    "vcage generate \"press the bell\" --episodes three   # a word, not a number\n"
                    "vcage plan \"press the bell\" --planer llm\nvcage frobnicate x\n```\n"
                    "```\n$ vcage report out/x --out r.html\n```\n")
    rotted, checked = rotted_lines([page])
    assert checked == 6, checked
    assert [r.split(": ", 2)[2][:30] for r in rotted] == [
        "Input should be a valid intege", "No such option: --planer", "no such command",
        "--stride is no option of vcage"], rotted


@pytest.mark.slow
def test_the_readme_example_runs(tmp_path: Path) -> None:
    """The README's "make your own dataset" block, line by line in a fresh directory, with 2
    episodes instead of 20; the dataset verifies and the report is written."""
    text = (ROOT / "README.md").read_text()
    block = text.split("## Make your own dataset", 1)[1].split("```bash", 1)[1].split("```", 1)[0]
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}:{os.environ['PATH']}", "LP_NUM_THREADS": "1"}
    ran = 0
    for line in block.strip().splitlines():
        line = line.split(" #")[0].strip()
        if line.startswith("source "):
            continue
        line = line.replace("--episodes 20", "--episodes 2")
        done = subprocess.run(line, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True,
                              timeout=900, check=False)
        assert done.returncode == 0, (line, done.stdout[-2000:], done.stderr[-2000:])
        ran += 1
    assert ran == 4 and (tmp_path / "mouse.html").stat().st_size > 10_000


def test_the_package_diagram_of_the_architecture_is_the_codes() -> None:
    stale = package_diagram.check(ROOT / "docs" / "ARCHITECTURE.md")
    assert stale is None, stale


def test_a_stale_package_diagram_is_caught(tmp_path: Path) -> None:
    page = tmp_path / "ARCHITECTURE.md"
    fresh = package_diagram.diagram()
    edge = next(line for line in fresh.splitlines() if " --> " in line)
    missing = fresh.replace(f"{edge}\n", "")  # the diagram less one edge
    page.write_text(f"# A\n\n{package_diagram.START}\n{missing}\n{package_diagram.END}\n")
    stale = package_diagram.check(page)
    assert stale is not None and f"+ {edge.strip()}" in stale and "--write docs/ARCHITECTURE.md" in stale
    assert package_diagram.main(["--check", str(page)]) == 1
    package_diagram.main(["--write", str(page)])
    assert package_diagram.check(page) is None and page.read_text().startswith("# A\n\n")
