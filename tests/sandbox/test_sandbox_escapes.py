"""The escape corpus: every known way out is blocked, by the static check, the child, or the parent."""

from __future__ import annotations

import os
import socket
import threading
from pathlib import Path

import pytest
from sandbox_escape_corpus import ESCAPES, blocked, skills, snapshot

from vcage.sandbox import Limits, run_program
from vcage.sandbox.runner import execute

LIMITS = Limits(cpu_seconds=1, memory_mb=256, wall_seconds=1.5)  # loops end at 1 s CPU or 1.5 s wall


@pytest.mark.parametrize("name", sorted(ESCAPES))
def test_every_escape_of_the_corpus_is_blocked(name: str) -> None:
    result = run_program(ESCAPES[name], skills(), snapshot(), LIMITS)
    stopped, by = blocked(result)
    assert stopped, f"{name!r} was not blocked: {result}"
    assert by != "ran"


def test_a_correct_program_runs_and_is_not_blocked() -> None:
    code = "p = position('b')\nif p[1] > 0:\n    pick_and_place(obj='a', xy=(p[0], p[1] - 0.14))\nretreat()\n"
    result = run_program(code, skills(), snapshot())
    assert result.ok, result.describe()
    assert [c.skill for c in result.calls] == ["pick_and_place", "retreat"]
    assert result.calls[0].args == {"obj": "a", "xy": [0.55, pytest.approx(-0.04)]}
    assert blocked(result) == (False, "ran")


# The second layer on its own: the static check is bypassed, the child must still hold.
WALK = ("w = [c for c in ().__class__.__bases__[0].__subclasses__() if c.__name__ == '_wrap_close'][0]\n"
        "g = w.__init__.__globals__\nb = g['__builtins__']\n")


def _unchecked(code: str):  # type: ignore[no-untyped-def]
    return execute(code, skills(), snapshot())


def test_the_child_alone_refuses_files_processes_and_imports(tmp_path: Path) -> None:
    target = tmp_path / "pwned"
    attempts = {
        "open for writing": f"b['open']({str(target)!r}, 'w').write('x')\n",
        "os.open": f"g['open']({str(target)!r}, 65)\n",
        "os.system": f"g['system']('touch {target}')\n",
        "fork": "g['fork']()\n",
        "import": "b['__import__']('socket')\n",
        "exec via builtins": "b['exec']('x = 1')\n",
        "compile via builtins": "b['compile']('1', 'f', 'eval')\n",
        "listdir": "g['listdir']('/')\n",
        "read a file": "b['open']('/etc/hostname').read()\n",
    }
    for what, code in attempts.items():
        result = _unchecked(WALK + code)
        assert result.status == "blocked", (what, result)
        assert "not allowed" in result.error
    assert not target.exists()


def test_the_child_sees_no_environment_variables_and_an_empty_directory(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("OPENAI_API_KEY", "sk-very-secret")
    result = _unchecked(WALK + "print(g['environ'])\nprint(g['getcwd']())\n")
    assert result.ok, result
    env, cwd = result.log
    assert "sk-very-secret" not in env and "OPENAI_API_KEY" not in env
    assert "vcage-sandbox-" in cwd and not os.path.exists(cwd)  # a fresh directory, removed after


def test_the_child_cannot_reach_the_network() -> None:
    hits: list[bytes] = []
    server = socket.create_server(("127.0.0.1", 0))
    port = server.getsockname()[1]
    server.settimeout(1)

    def accept() -> None:
        try:
            conn, _ = server.accept()
            hits.append(conn.recv(10))
        except OSError:
            pass

    thread = threading.Thread(target=accept)
    thread.start()
    code = WALK + f"s = b['__import__']('socket')\ns.create_connection(('127.0.0.1', {port})).send(b'x')\n"
    result = _unchecked(code)
    server.close()
    thread.join()
    assert result.status == "blocked" and hits == []
