"""The command line. Each command parses its arguments, calls one library function and turns
``Colregs9Error`` into one ``Error: …`` line and an exit code. No logic lives here."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

import typer

from . import __version__
from .errors import Colregs9Error

app = typer.Typer(
    name="colregs9",
    help="COLREGs rule 9 (narrow channels) audits of historical AIS.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


@contextmanager
def _user_errors() -> Iterator[None]:
    try:
        yield
    except Colregs9Error as exc:
        typer.echo(f"Error: {exc}", err=True)
        raise typer.Exit(exc.exit_code) from None


def _version(value: bool) -> None:
    if value:
        typer.echo(f"colregs9 {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Show the version and exit."
    ),
) -> None:
    """COLREGs rule 9 (narrow channels) audits of historical AIS.

    Example: colregs9 stats fixtures/ais/aisdk_2024-09-09_sample.csv
    """
