"""What every ``roverlab`` command group shares: how its typer app is made and run alone.

Each group (``roverlab slam``, ``roverlab map``, ...) is mounted by the root command and can
also run on its own (``python -m roverlab.cli.maps``); either way ``-h`` is ``--help``,
tracebacks are plain and a :class:`~roverlab.errors.RoverlabError` is one ``error:`` line on
stderr with exit code 2.
"""

from __future__ import annotations

import sys
from typing import Any

import typer

from roverlab.errors import RoverlabError

__all__ = ["command_app", "run_app"]


def command_app(**settings: Any) -> typer.Typer:
    """A command group's app: ``typer.Typer(**settings)`` with ``-h``/``--help`` and plain
    tracebacks."""
    return typer.Typer(
        **settings,
        pretty_exceptions_enable=False,
        context_settings={"help_option_names": ["-h", "--help"]},
    )


def run_app(app: typer.Typer, argv: list[str] | None, prog_name: str) -> None:
    """Run ``app`` as ``prog_name``: user errors become one line on stderr and exit code 2."""
    try:
        app(args=argv, prog_name=prog_name, standalone_mode=True)
    except RoverlabError as err:
        print(f"error: {err}", file=sys.stderr)
        sys.exit(2)
