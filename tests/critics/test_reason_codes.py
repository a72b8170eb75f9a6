"""Reason codes: every rejection of a critic names its causes in ``Verdict.codes`` (``pressed.too_shallow``),
so rejections can be counted by cause without reading their text.

Each failure of an image check returns a :class:`~vcage.critics.base.Reason` whose code is in
:data:`~vcage.critics.image.reasons.REASON_CODES`; a failure without one would be counted as
``<predicate>.unspecified``. The source of every check is read here (its syntax tree) so that a new
``return False, "..."`` fails a test even where no stored observation reaches it.
"""

from __future__ import annotations

import ast
import pickle
import re
from pathlib import Path

import pytest

from critics.recipes import HERE, observed, planned
from vcage.critics.base import Reason, Verdict
from vcage.critics.image import IMAGE_CHECKS, UNSPECIFIED, ImageCritic
from vcage.critics.image.reasons import REASON_CODES
from vcage.critics.oracle import OracleCritic

CRITIC, ORACLE = ImageCritic(), OracleCritic()
PACKAGE = Path(__file__).parents[2] / "src" / "vcage" / "critics" / "image"
CHECK = "tuple[bool, str]"  # how a check's result is annotated


def _trees() -> dict[str, ast.Module]:
    return {path.name: ast.parse(path.read_text()) for path in sorted(PACKAGE.glob("*.py"))}


def _functions(trees: dict[str, ast.Module]) -> dict[str, ast.FunctionDef]:
    return {node.name: node for tree in trees.values() for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef)}


def _returns(node: ast.FunctionDef) -> str:
    return ast.unparse(node.returns) if node.returns is not None else ""


def _bad_returns(trees: dict[str, ast.Module]) -> list[str]:
    """Where a check can fail with a ``why`` that is not a Reason: each ``return`` of a check (a
    function annotated ``tuple[bool, str]``) whose first element is not ``True`` must return, second,
    a ``Reason(...)``, a call to a helper annotated to return a Reason, or a name the same function
    assigned only from such (or from unpacking another check's result); a helper annotated to return a
    Reason returns only those or None. ``(False, X) if ... else ...`` is judged branch by branch."""
    functions = _functions(trees)
    checks = {name for name, f in functions.items() if _returns(f) == CHECK}
    helpers = {name for name, f in functions.items() if "Reason" in _returns(f)}
    bad: list[str] = []

    def called(expr: ast.expr, names: set[str]) -> bool:
        return isinstance(expr, ast.Call) and isinstance(expr.func, ast.Name) and expr.func.id in names

    def reason(expr: ast.expr, f: ast.FunctionDef, none: bool, depth: int = 0) -> bool:
        if isinstance(expr, ast.Constant) and expr.value is None:
            return none
        if called(expr, {"Reason"} | helpers):
            return True
        if isinstance(expr, ast.BoolOp):
            return all(reason(v, f, True, depth) for v in expr.values)
        if isinstance(expr, ast.IfExp):
            return reason(expr.body, f, True, depth) and reason(expr.orelse, f, True, depth)
        if isinstance(expr, ast.Name) and depth < 5:
            sources = []
            for node in ast.walk(f):
                if isinstance(node, ast.Assign):
                    for target in node.targets:
                        if isinstance(target, ast.Name) and target.id == expr.id:
                            sources.append(reason(node.value, f, True, depth + 1))
                        elif isinstance(target, ast.Tuple) and any(
                                isinstance(t, ast.Name) and t.id == expr.id for t in target.elts):
                            sources.append(called(node.value, checks | helpers))  # ok, why = _on(...)
            return bool(sources) and all(sources)
        return False

    def check_return(value: ast.expr, f: ast.FunctionDef, where: str) -> None:
        if isinstance(value, ast.IfExp):
            check_return(value.body, f, where)
            check_return(value.orelse, f, where)
        elif isinstance(value, ast.Tuple) and len(value.elts) == 2:
            first, why = value.elts
            if not (isinstance(first, ast.Constant) and first.value is True) and not reason(why, f, False):
                bad.append(f"{where}: return {ast.unparse(value)}")
        elif not called(value, checks):
            bad.append(f"{where}: return {ast.unparse(value)}")

    for module, tree in trees.items():
        for f in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)):
            for ret in (n for n in ast.walk(f) if isinstance(n, ast.Return) and n.value is not None):
                assert ret.value is not None
                where = f"{module}:{ret.lineno} ({f.name})"
                if f.name in checks:
                    check_return(ret.value, f, where)
                elif (f.name in helpers and not isinstance(ret.value, ast.Tuple)  # a tuple: _drawer's measure
                      and not reason(ret.value, f, True)):
                    bad.append(f"{where}: return {ast.unparse(ret.value)}")
    return bad


def _codes_in_source(trees: dict[str, ast.Module]) -> dict[str, int]:
    """Each code a ``Reason(...)`` of the image package names, and how often."""
    codes: dict[str, int] = {}
    for tree in trees.values():
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "Reason":
                first = node.args[0]
                assert isinstance(first, ast.Constant) and isinstance(first.value, str), ast.unparse(node)
                codes[first.value] = codes.get(first.value, 0) + 1
    return codes


def test_every_failure_of_an_image_check_returns_a_reason() -> None:
    trees = _trees()
    checks = {name for name, f in _functions(trees).items() if _returns(f) == CHECK}
    registered = {IMAGE_CHECKS.get(name).__name__ for name in IMAGE_CHECKS.names()}
    assert registered - {"<lambda>"} <= checks  # every registered check is one read here
    assert {"_rests_on", "_front_support", "_in_drawer", "_side"} <= checks  # and those they return
    assert _bad_returns(trees) == []


def test_the_reason_check_catches_a_failure_without_a_code() -> None:
    """The check above, shown a plain string where a Reason should be (as a new check might be written)."""
    tree = ast.parse('def _check(obs, a) -> tuple[bool, str]:\n'
                     '    if obs:\n        return False, f"{a} is missing"\n'
                     '    ok, why = _check(obs, a)\n    if not ok:\n        return ok, why\n'
                     '    text = "a plain string"\n    return obs > 1, text\n')
    assert sorted(_bad_returns({"new.py": tree})) == ["new.py:3 (_check): return (False, f'{a} is missing')",
                                                      "new.py:8 (_check): return (obs > 1, text)"]


def test_every_code_returned_is_in_the_table_and_every_code_in_the_table_is_returned() -> None:
    used = _codes_in_source(_trees())
    assert sorted(used) == sorted(REASON_CODES)
    assert all(re.fullmatch(r"[a-z]+(_[a-z]+)*", code) for code in REASON_CODES)
    assert all(meaning.strip() for meaning in REASON_CODES.values())
    assert UNSPECIFIED not in REASON_CODES


def test_every_stored_rejection_names_a_code_for_each_failed_check() -> None:
    """Every stored observation, judged: a rejection has one code per failed predicate, in their order,
    each a predicate's name and a code of the table; an acceptance has none."""
    for path in sorted(HERE.glob("*.npz")):
        obs = observed(path.stem).obs
        verdict = CRITIC.judge(obs)
        failed = [p.name for p in obs.subtask.predicates if not verdict.details["checks"][str(p)]]
        assert [code.split(".")[0] for code in verdict.codes] == failed, path.stem
        assert all(code.split(".")[1] in REASON_CODES for code in verdict.codes), (path.stem, verdict.codes)
        assert bool(verdict.codes) is not verdict.accept, path.stem


@pytest.mark.parametrize(("name", "codes", "oracle"), [
    ("pressed-press_light-0", ("pressed.too_shallow",), ("pressed.false",)),
    ("pressed-press_miss-0", ("pressed.no_contact",), ("pressed.false",)),
    ("bell-behind-a-cup-press_miss-0", ("pressed.not_covered",), ("pressed.false",)),
    ("mouse-onto-a-block-on-the-pad", ("on.on_other_object",), ("on.false",)),
    ("on-off_target-1", ("on.not_over_target",), ("on.false",)),
    ("inside-no_release-0", ("inside.not_over_target", "released.still_touching"),
     ("inside.false", "released.false")),
    ("block-put-down-where-another-stands", ("on_table.too_high",), ("on_table.false",)),
    ("opened-pull_short-1", ("opened.drawer_not_open",), ("opened.false",)),
    ("board-put-back-unturned", ("facing.facing_away",), ("facing.false",)),
    ("left_of-wrong_object-0", ("left_of.wrong_side",), ("left_of.false",)),
    ("near-off_target-0", ("near.too_far",), ("near.false",)),
])
def test_a_rejected_subtask_names_its_cause(name: str, codes: tuple[str, ...],
                                            oracle: tuple[str, ...]) -> None:
    case = observed(name)
    verdict = CRITIC.judge(case.obs)
    assert not verdict.accept and verdict.codes == codes, verdict.reason
    assert verdict.to_dict()["codes"] == list(codes)
    truth = ORACLE.judge(case.obs)
    assert not truth.accept and truth.codes == oracle, truth.reason


def test_an_accepted_verdict_is_stored_as_before_without_codes() -> None:
    case = observed(planned("pressed"))
    for verdict in (CRITIC.judge(case.obs), ORACLE.judge(case.obs)):
        assert verdict.accept and verdict.codes == (), verdict.reason
        assert "codes" not in verdict.to_dict()
    checks = {str(p): True for p in case.obs.subtask.predicates}
    assert CRITIC.judge(case.obs).to_dict() == {"accept": True, "reason": "all image checks pass",
                                                "details": {"checks": checks}}
    assert Verdict(True, "fine").to_dict() == {"accept": True, "reason": "fine"}


def test_a_reason_is_its_text_and_keeps_its_code() -> None:
    why = Reason("too_shallow", "the hand stopped 3.1 mm short of pressing bell")
    assert why == "the hand stopped 3.1 mm short of pressing bell" and why.code == "too_shallow"
    assert f"pressed(bell): {why}" == "pressed(bell): the hand stopped 3.1 mm short of pressing bell"
    copy = pickle.loads(pickle.dumps(why))
    assert copy == why and copy.code == "too_shallow"
