"""The one place a command's :class:`~vcage.errors.VcageError` becomes output and an exit code.

Exit codes: 0 the command did what was asked (for ``generate``: the dataset holds every episode
asked for); 1 an unexpected crash (a bug: please report it with the traceback); 2 bad input
(an invalid option, an instruction that cannot be grounded, a directory that is not a dataset);
3 a partial result (``generate`` accepted fewer episodes than asked: rerun with ``--total``);
4 a model backend is unavailable (unreachable, timing out, refusing requests); 5 a corrupt
dataset (``vcage verify --repair`` drops the damaged episodes).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import NoReturn, ParamSpec, TypeVar

import typer
from rich.markup import escape

from vcage.cli._app import console
from vcage.errors import BackendError, ConfigError, CorruptDatasetError, VcageError

P = ParamSpec("P")
R = TypeVar("R")

MARKER = "__vcage_cli_errors__"  # set on every callback wrapped by :func:`cli_errors`
EXIT_BAD_INPUT, EXIT_PARTIAL, EXIT_BACKEND, EXIT_CORRUPT = 2, 3, 4, 5


def exit_code(exc: VcageError) -> int:
    """The exit code of a command that raised ``exc``."""
    if isinstance(exc, BackendError) and not isinstance(exc, ConfigError):
        return EXIT_BACKEND
    if isinstance(exc, CorruptDatasetError):
        return EXIT_CORRUPT
    return EXIT_BAD_INPUT


def cli_errors(command: Callable[P, R]) -> Callable[P, R]:
    """Turn a ``VcageError`` raised by ``command`` into ``error: <message>`` (red) and its exit code.

    Apply it under ``@app.command``; ``functools.wraps`` keeps the signature Typer reads.
    """

    @functools.wraps(command)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return command(*args, **kwargs)
        except VcageError as exc:
            fail(str(exc), exit_code(exc))

    setattr(wrapper, MARKER, True)
    return wrapper


def fail(message: str, code: int) -> NoReturn:
    """Print ``error: <message>`` and end the command with ``code``."""
    console.print(f"[red]error:[/red] {escape(message)}", highlight=False, soft_wrap=True)
    raise typer.Exit(code)
