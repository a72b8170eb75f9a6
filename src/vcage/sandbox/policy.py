"""The static half of the sandbox: an allow-list over the syntax tree of a generated program.

A program is checked before it is run, in the parent, on the tree ``ast.parse`` builds (never
compiled or run here). Identifiers are checked as parsed, i.e. after Python's NFKC normalisation,
so ``ｅｘｅｃ`` (fullwidth) is the name ``exec`` and is refused like it. Only a small language is
allowed: assignments, ``if``/``for``/``while``, arithmetic, comparisons, literals, subscripts,
calls of the skill API, of a few safe builtins and of a few container methods. Everything that
leads out of that language is refused: imports in every spelling, names or attributes that start
with ``_`` (dunders, private names), the dangerous builtins (``eval``, ``exec``, ``getattr``,
``open``, ``compile``, ``globals``, ``vars``, ``breakpoint``, ...), ``.format``/``.format_map``,
functions, classes, lambdas, generators (their frames), ``try``, ``with``, ``global``, and
programs too long or nested too deeply. What the tree cannot show (loops that never end, memory
bombs) is the child process's resource limits' job (:mod:`vcage.sandbox.runner`).
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from dataclasses import dataclass

from vcage.errors import CodeRejectedError

MAX_CHARS = 4000  # source length of one program
MAX_NODES = 1500  # syntax-tree nodes of one program
MAX_DEPTH = 24  # nesting depth of the syntax tree

# Builtins the child provides (see child.py); any other free name must be the program's own or the API's.
SAFE_BUILTINS = frozenset({"abs", "min", "max", "round", "len", "range", "float", "int", "bool", "str",
                           "list", "tuple", "dict", "enumerate", "zip", "sum", "sorted", "reversed",
                           "any", "all", "print"})
# Refused by name with a reason of their own (the allow-list would refuse them anyway).
BANNED_NAMES = frozenset({"eval", "exec", "compile", "getattr", "setattr", "delattr", "hasattr", "open",
                          "globals", "locals", "vars", "dir", "breakpoint", "input", "help", "type",
                          "object", "super", "memoryview", "classmethod", "staticmethod", "property",
                          "exit", "quit", "id", "iter", "next", "importlib", "os", "sys", "socket",
                          "subprocess", "builtins", "format", "chr", "ord", "bytes", "bytearray"})
# Container methods a program may call; every other attribute is refused.
SAFE_ATTRIBUTES = frozenset({"append", "extend", "insert", "pop", "index", "count", "sort", "reverse",
                             "copy", "get", "items", "keys", "values"})
BANNED_ATTRIBUTES = frozenset({"format", "format_map", "gi_frame", "gi_code", "cr_frame", "ag_frame",
                               "tb_frame", "tb_next", "f_globals", "f_locals", "f_back", "f_builtins",
                               "func_globals", "mro"})

_ALLOWED_NODES: tuple[type[ast.AST], ...] = (
    ast.Module, ast.Expr, ast.Assign, ast.AugAssign, ast.If, ast.For, ast.While, ast.Break, ast.Continue,
    ast.Pass, ast.BoolOp, ast.BinOp, ast.UnaryOp, ast.Compare, ast.IfExp, ast.Call, ast.keyword,
    ast.Name, ast.Constant, ast.List, ast.Tuple, ast.Dict, ast.Subscript, ast.Slice, ast.Attribute,
    ast.ListComp, ast.comprehension, ast.Load, ast.Store, ast.boolop, ast.operator, ast.unaryop,
    ast.cmpop, ast.expr_context,
)


@dataclass(frozen=True)
class Violation:
    line: int
    what: str

    def __str__(self) -> str:
        return f"line {self.line}: {self.what}"


def check(code: str, api: Iterable[str]) -> ast.Module:
    """The parsed program, if it keeps to the allowed language and calls only ``api`` and safe
    builtins; otherwise :class:`CodeRejectedError` listing every violation (line and reason)."""
    if not isinstance(code, str):
        raise CodeRejectedError(f"a program must be text, got {type(code).__name__}")
    if len(code) > MAX_CHARS:
        raise CodeRejectedError(f"the program has {len(code)} characters, more than {MAX_CHARS}; "
                                "write a shorter program (one subtask is a few skill calls)")
    try:
        tree = ast.parse(code, "<subtask>", "exec")
    except SyntaxError as exc:
        raise CodeRejectedError(f"not valid Python: {exc.msg} (line {exc.lineno})") from None
    except (ValueError, RecursionError, MemoryError) as exc:  # null bytes, nesting beyond the parser
        raise CodeRejectedError(f"not parseable Python: {type(exc).__name__}: {exc}"[:300]) from None
    problems = _violations(tree, frozenset(api))
    if problems:
        listed = "; ".join(str(p) for p in problems[:10])
        more = f" (and {len(problems) - 10} more)" if len(problems) > 10 else ""
        raise CodeRejectedError(f"the program uses what the sandbox does not allow: {listed}{more}")
    return tree


def _violations(tree: ast.Module, api: frozenset[str]) -> list[Violation]:
    out: list[Violation] = []
    nodes = list(ast.walk(tree))
    if len(nodes) > MAX_NODES:
        return [Violation(1, f"{len(nodes)} syntax nodes, more than {MAX_NODES}")]
    depth = _depth(tree)
    if depth > MAX_DEPTH:
        return [Violation(1, f"nesting depth {depth}, more than {MAX_DEPTH}")]
    assigned = {n.id for n in nodes if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    known = api | SAFE_BUILTINS | assigned
    for node in nodes:
        line = getattr(node, "lineno", 1)
        if not isinstance(node, _ALLOWED_NODES):
            out.append(Violation(line, _node_reason(node)))
        elif isinstance(node, ast.Name):
            out += [Violation(line, why) for why in _name_reasons(node.id, known)]
        elif isinstance(node, ast.Attribute):
            out += [Violation(line, why) for why in _attribute_reasons(node.attr)]
        elif isinstance(node, ast.keyword) and node.arg is not None and node.arg.startswith("_"):
            out.append(Violation(line, f"keyword argument {node.arg!r} starts with '_'"))
        elif isinstance(node, ast.keyword) and node.arg is None:
            out.append(Violation(line, "'**' argument unpacking"))
    return out


def _node_reason(node: ast.AST) -> str:
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        return "import (programs may not import anything; the skill API is already there)"
    name = type(node).__name__
    hints = {"FunctionDef": "function definition", "AsyncFunctionDef": "function definition",
             "Lambda": "lambda", "ClassDef": "class definition", "GeneratorExp": "generator expression",
             "Try": "try statement", "TryStar": "try statement", "With": "with statement",
             "Global": "global statement", "Nonlocal": "nonlocal statement", "Starred": "'*' unpacking",
             "NamedExpr": "assignment expression", "JoinedStr": "f-string", "FormattedValue": "f-string",
             "Yield": "yield", "YieldFrom": "yield", "Await": "await", "Delete": "del statement",
             "Raise": "raise statement", "Assert": "assert statement", "Match": "match statement"}
    return f"{hints.get(name, name)} is not allowed"


def _name_reasons(name: str, known: frozenset[str] | set[str]) -> list[str]:
    if name.startswith("_"):
        return [f"name {name!r} starts with '_' (dunder and private names are not allowed)"]
    if name in BANNED_NAMES:
        return [f"name {name!r} is not allowed"]
    if name not in known:
        return [f"unknown name {name!r} (use the skill API, a safe builtin or a variable you assign)"]
    return []


def _attribute_reasons(attr: str) -> list[str]:
    if attr.startswith("_"):
        return [f"attribute {attr!r} starts with '_' (dunder and private attributes are not allowed)"]
    if attr in BANNED_ATTRIBUTES:
        return [f"attribute {attr!r} is not allowed"]
    if attr not in SAFE_ATTRIBUTES:
        return [f"attribute {attr!r} is not allowed (allowed: {', '.join(sorted(SAFE_ATTRIBUTES))})"]
    return []


def _depth(tree: ast.AST) -> int:
    """The deepest nesting of the tree, walked without recursion (deep trees are the attack)."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack.extend((child, d + 1) for child in ast.iter_child_nodes(node))
    return deepest
