"""The sandbox's figures: escape corpus blocked, timeout kill latency, overhead per program, reruns.

    .venv/bin/python benchmarks/sandbox.py
    .venv/bin/python benchmarks/sandbox.py --runs 100 --kills 10

Prints: the share of the escape corpus (tests/sandbox/sandbox_escape_corpus.py) blocked through
the full path (static check, child, parent's argument check) and by which layer; the share of
harmful programs the child blocks on its own (static check bypassed); how long after its wall-clock
limit a looping child is dead (target: within limit + 1 s); the wall time of one small program
(spawn, run, answer; target < 150 ms); and whether reruns record bit-identical calls.
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import statistics
import sys
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "sandbox"))

from sandbox_escape_corpus import ESCAPES, blocked, skills, snapshot  # noqa: E402

from vcage.sandbox import Limits, run_program  # noqa: E402
from vcage.sandbox.runner import execute  # noqa: E402

WALK = ("w = [c for c in ().__class__.__bases__[0].__subclasses__() if c.__name__ == '_wrap_close'][0]\n"
        "g = w.__init__.__globals__\nb = g['__builtins__']\n")
HARMFUL = {  # the static check bypassed: the child alone must stop each
    "write a file": "b['open']('pwned', 'w').write('x')\n",
    "os.open": "g['open']('pwned', 65)\n",
    "os.system": "g['system']('id')\n",
    "fork": "g['fork']()\n",
    "import socket": "b['__import__']('socket')\n",
    "exec": "b['exec']('x = 1')\n",
    "compile": "b['compile']('1', 'f', 'eval')\n",
    "read /etc/hostname": "b['open']('/etc/hostname').read()\n",
    "listdir": "g['listdir']('/')\n",
    "loop": "while True:\n    pass\n",
    "memory": "x = [0] * 10 ** 10\n",
}
PROGRAMS = [
    "pick_and_place(obj='a', target='b')\n",
    "p = position('b')\npick_and_place(obj='a', xy=(p[0], p[1] - 0.14))\nretreat()\n",
    "for n in objects():\n    q = pose(n)\n    push(obj=n, direction=(1.0, q[3]), distance=0.05)\n",
]


def corpus(limits: Limits) -> None:
    layers: Counter[str] = Counter()
    missed = []
    for name, code in ESCAPES.items():
        stopped, by = blocked(run_program(code, skills(), snapshot(), limits))
        layers[by] += 1
        if not stopped:
            missed.append(name)
    n = len(ESCAPES)
    print(f"escape corpus: {n - len(missed)}/{n} blocked ({100 * (n - len(missed)) / n:.1f} %); by layer: "
          + ", ".join(f"{k} {v}" for k, v in sorted(layers.items()))
          + (f"; NOT blocked: {missed}" if missed else ""))
    alone = Counter(execute(WALK + code if "g[" in code or "b[" in code else code, skills(), snapshot(),
                            limits).status for code in HARMFUL.values())
    held = sum(v for k, v in alone.items() if k != "ok")
    print(f"child alone (static check bypassed): {held}/{len(HARMFUL)} harmful programs stopped; "
          + ", ".join(f"{k} {v}" for k, v in sorted(alone.items())))
    seen = execute(WALK + "print(list(g['environ']))\n", skills(), snapshot(), limits).log[0]
    leaked = sorted(set(os.environ) & set(ast.literal_eval(seen)))
    print(f"environment the child sees: {seen} (the parent has {len(os.environ)} variables; "
          f"leaked: {leaked or 'none'})")


def kills(repeats: int) -> None:
    for wall in (0.5, 1.0, 2.0):
        late = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            result = run_program("while True:\n    pass\n", skills(), snapshot(),
                                 Limits(cpu_seconds=60, wall_seconds=wall))
            assert result.status == "timeout", result
            late.append(time.perf_counter() - t0 - wall)
        print(f"timeout kill, limit {wall:.1f} s (n={repeats}): dead after limit + "
              f"{statistics.median(late) * 1000:.0f} ms median, + {max(late) * 1000:.0f} ms max "
              "(target: + 1000 ms)")


def overhead(runs: int) -> None:
    for code in PROGRAMS[:2]:
        times = []
        for _ in range(runs):
            t0 = time.perf_counter()
            result = run_program(code, skills(), snapshot())
            times.append(time.perf_counter() - t0)
            assert result.ok, result
        times.sort()
        print(f"overhead per program ({len(code.splitlines())} lines, n={runs}): median "
              f"{statistics.median(times) * 1000:.1f} ms, p95 {times[int(0.95 * (runs - 1))] * 1000:.1f} ms, "
              f"max {times[-1] * 1000:.1f} ms (target < 150 ms)")


def reruns(runs: int) -> None:
    same = 0
    for code in PROGRAMS:
        answers = {json.dumps([c.to_dict() for c in run_program(code, skills(), snapshot()).calls])
                   for _ in range(runs)}
        same += len(answers) == 1
    print(f"reruns: {same}/{len(PROGRAMS)} programs recorded bit-identical calls over {runs} runs each")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=50, help="runs per program for overhead and reruns")
    parser.add_argument("--kills", type=int, default=5, help="timeouts per wall-clock limit")
    args = parser.parse_args()
    corpus(Limits(cpu_seconds=1, wall_seconds=3.0))
    kills(args.kills)
    overhead(args.runs)
    reruns(args.runs // 5 or 1)


if __name__ == "__main__":
    main()
