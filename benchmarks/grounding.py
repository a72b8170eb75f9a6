"""Grounding accuracy of the offline planner on a hand-written evaluation set.

Each sentence of ``tests/planning/data/grounding.jsonl`` carries its expected outcome: a library
goal (optionally with objects the plan must contain, e.g. ``cup:blue``), the exact subtasks of an
explicit instruction, or ``"refuse"``. A plan that does not match its expectation, or any plan
for a sentence that should be refused, is a *wrong plan*: the dangerous case, because generation
would write verified episodes labelled with the sentence. Prints per category:

- correct plan: expected a plan and got that plan (of the sentences expecting a plan);
- wrong plan: got a plan that is not the expected one (of all sentences; must be 0);
- correct refusal: expected a refusal and got a ``PlanningError`` (of the sentences to refuse);
- refused groundable: expected a plan and got a ``PlanningError`` (of the sentences expecting a plan);
- crash: any other exception;
- echo: refusals whose message repeats more than 250 characters of the instruction.

Run from the repository root: ``.venv/bin/python benchmarks/grounding.py [--verbose] [--data PATH]``.
Object descriptors are ``type[:colour][@small]``, numbered ``#2``, ``#3`` when a plan holds two
objects with the same descriptor; subtasks are ``[on|in, obj, target]`` (by the success predicate)
or ``[press, obj(, point)]``.
"""

from __future__ import annotations

import argparse
import json
import time
from collections import Counter, defaultdict
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vcage.errors import PlanningError
from vcage.planning import OfflinePlanner, Plan

DATA = Path(__file__).resolve().parent.parent / "tests" / "planning" / "data" / "grounding.jsonl"
ECHO_LIMIT = 250  # a refusal repeating a longer piece of the instruction counts as an unbounded echo
OUTCOMES = ("correct_plan", "wrong_plan", "correct_refusal", "refused_groundable", "crash")


@dataclass(frozen=True)
class Case:
    id: str
    category: str
    text: str
    expect: Any  # "refuse" | {"goal": name, "objects": [...]} | {"subtasks": [[...], ...]}


@dataclass(frozen=True)
class Result:
    case: Case
    outcome: str
    detail: str
    echo: bool = False


def load(path: Path = DATA) -> list[Case]:
    cases = []
    for line in path.read_text().splitlines():
        if not line.strip():
            continue
        row = json.loads(line)
        text = row["text"] * int(row.get("repeat", 1))
        cases.append(Case(row["id"], row["category"], text, row["expect"]))
    return cases


def descriptors(plan: Plan) -> dict[str, str]:
    """Plan object name -> ``type[:colour][@small]``, numbered when two objects look alike."""
    seen: Counter[str] = Counter()
    out = {}
    for o in plan.objects:
        small = o.scale is not None and o.scale < 1
        d = o.type + (f":{o.color}" if o.color else "") + ("@small" if small else "")
        seen[d] += 1
        out[o.name] = d if seen[d] == 1 else f"{d}#{seen[d]}"
    return out


def canonical(plan: Plan) -> list[list[str]]:
    names = descriptors(plan)
    steps: list[list[str]] = []
    for st in plan.subtasks:
        obj = names.get(str(st.args.get("obj")), "?")
        if st.skill == "press":
            steps.append(["press", obj] + ([str(st.args["point"])] if st.args.get("point") else []))
        elif st.skill == "pick_and_place" and "target" in st.args:
            rel = next((p.name for p in st.predicates if p.name in ("on", "inside")), "?")
            steps.append(["in" if rel == "inside" else rel, obj, names.get(str(st.args["target"]), "?")])
        elif st.skill == "hang":
            steps.append(["hang", obj, names.get(str(st.args.get("target")), "?")])
        else:
            steps.append([st.skill, obj])
    return steps


def judge(case: Case, plan: Plan) -> tuple[bool, str]:
    """Whether ``plan`` is the expected one, and what it was."""
    goal = getattr(plan, "goal", None)
    got = f"goal {goal}" if goal else f"subtasks {canonical(plan)}"
    if case.expect == "refuse":
        return False, f"expected a refusal, got {got}"
    if "goal" in case.expect:
        have = set(descriptors(plan).values())
        missing = [d for d in case.expect.get("objects", []) if d not in have]
        ok = goal == case.expect["goal"] and not missing
        return ok, got + (f" without {missing}" if missing else "")
    want = case.expect["subtasks"]
    steps = canonical(plan)
    used = {s[1] for s in want} | {s[2] for s in want if s[0] in ("on", "in", "hang")}
    extra = set(descriptors(plan).values()) - used
    ok = goal is None and steps == want and not extra
    return ok, got + (f" with extra objects {sorted(extra)}" if extra else "")


def _echoes(text: str, message: str) -> bool:
    text, message = " ".join(text.split()).lower(), message.lower()
    if len(text) <= ECHO_LIMIT:
        return False
    width = ECHO_LIMIT - 49  # any echo longer than ECHO_LIMIT holds a window starting at a multiple of 50
    return any(text[i:i + width] in message for i in range(0, len(text) - width + 1, 50))


def evaluate(cases: Iterable[Case], planner: Any | None = None) -> list[Result]:
    planner = planner or OfflinePlanner()
    results = []
    for case in cases:
        try:
            plan = planner.plan(case.text)
        except PlanningError as exc:
            msg = str(exc)
            outcome = "correct_refusal" if case.expect == "refuse" else "refused_groundable"
            results.append(Result(case, outcome, msg, _echoes(case.text, msg)))
            continue
        except Exception as exc:  # noqa: BLE001 - a crash is an outcome to count
            results.append(Result(case, "crash", f"{type(exc).__name__}: {exc}"[:300]))
            continue
        ok, detail = judge(case, plan)
        results.append(Result(case, "correct_plan" if ok else "wrong_plan", detail))
    return results


def _frac(a: int, b: int) -> str:
    return f"{a}/{b} ({100 * a / b:.0f}%)" if b else "-"


def table(results: list[Result]) -> str:
    by: dict[str, list[Result]] = defaultdict(list)
    for r in results:
        by[r.case.category].append(r)
    head = (f"{'category':<18} {'n':>4}  {'correct plan':>14}  {'wrong plan':>12}  {'correct refusal':>15}  "
            f"{'refused groundable':>18}  {'crash':>5}  {'echo':>4}")
    lines = [head, "-" * len(head)]
    for cat, rs in [*by.items(), ("ALL", results)]:
        c = Counter(r.outcome for r in rs)
        want_plan = sum(r.case.expect != "refuse" for r in rs)
        want_refuse = len(rs) - want_plan
        if cat == "ALL":
            lines.append("-" * len(head))
        lines.append(f"{cat:<18} {len(rs):>4}  {_frac(c['correct_plan'], want_plan):>14}  "
                     f"{_frac(c['wrong_plan'], len(rs)):>12}  "
                     f"{_frac(c['correct_refusal'], want_refuse):>15}  "
                     f"{_frac(c['refused_groundable'], want_plan):>18}  {c['crash']:>5}  "
                     f"{sum(r.echo for r in rs):>4}")
    c = Counter(r.outcome for r in results)
    correct = c["correct_plan"] + c["correct_refusal"]
    longest = max((len(r.detail) for r in results if "refus" in r.outcome), default=0)
    lines.append(f"\naccuracy (correct plan or correct refusal): {_frac(correct, len(results))}; "
                 f"wrong plans: {_frac(c['wrong_plan'], len(results))}; "
                 f"longest refusal message: {longest} characters")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=DATA)
    ap.add_argument("--verbose", action="store_true", help="print every sentence that was not right")
    ap.add_argument("--record", action="store_true", help="write the figures to docs/results/grounding.json "
                    "(the results page)")
    args = ap.parse_args()
    cases = load(args.data)
    t0 = time.perf_counter()
    results = evaluate(cases)
    dt = time.perf_counter() - t0
    import vcage.planning

    print(f"offline planner from {Path(vcage.planning.__file__).parent}; {len(cases)} sentences in "
          f"{dt:.2f} s ({args.data.name})\n")
    print(table(results))
    shown = ("wrong_plan", "crash", "refused_groundable") if args.verbose else ("wrong_plan", "crash")
    bad = [r for r in results if r.outcome in shown or r.echo]
    if bad:
        print("\nnot right:" if args.verbose else "\nwrong plans, crashes, echoes (--verbose: all):")
        for r in bad:
            text = r.case.text if len(r.case.text) <= 90 else r.case.text[:87] + "..."
            print(f"  {r.case.id} [{r.outcome}{', echo' if r.echo else ''}] {text!r}: {r.detail[:160]}")
    if args.record:
        _record(results, cases)


def _record(results: list[Result], cases: list[Case]) -> None:
    import results as results_file  # benchmarks/results.py, beside this script

    c = Counter(r.outcome for r in results)
    want_plan = sum(r.case.expect != "refuse" for r in results)
    path = results_file.record(
        "grounding", "Grounding with the offline planner",
        "Does the offline planner turn a hand-written sentence into the right plan, or refuse it when it "
        "cannot be grounded, without ever running a wrong plan? The planner's rules were written with "
        "many of these sentences in view, so this is a regression figure, not a held-out one.",
        {"wrong plans": f"{c['wrong_plan']}/{len(results)}",
         "correct plans (of sentences that should plan)": f"{c['correct_plan']}/{want_plan}",
         "correct refusals (of sentences that should be refused)":
             f"{c['correct_refusal']}/{len(results) - want_plan}",
         "groundable sentences refused": f"{c['refused_groundable']}/{want_plan}",
         "crashes": str(c["crash"])},
        f"{len(cases)} sentences in {len({r.case.category for r in results})} categories "
        f"({want_plan} to plan, {len(results) - want_plan} to refuse)")
    print(f"recorded in {path}")


if __name__ == "__main__":
    main()
