"""The one place a command's :class:`~vcage.errors.VcageError` becomes output and an exit code."""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

import typer

from vcage.cli._app import console
from vcage.errors import VcageError

P = ParamSpec("P")
R = TypeVar("R")

MARKER = "__vcage_cli_errors__"  # set on every callback wrapped by :func:`cli_errors`


def cli_errors(command: Callable[P, R]) -> Callable[P, R]:
    """Turn a ``VcageError`` raised by ``command`` into ``error: <message>`` (red) and exit code 2.

    Apply it under ``@app.command``; ``functools.wraps`` keeps the signature Typer reads.
    """

    @functools.wraps(command)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        try:
            return command(*args, **kwargs)
        except VcageError as exc:
            console.print(f"[red]error:[/red] {exc}")
            raise typer.Exit(2) from None

    setattr(wrapper, MARKER, True)
    return wrapper
