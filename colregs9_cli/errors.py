"""The error hierarchy. The CLI prints ``Error: <message>`` and exits with ``exit_code``.

Messages name the file, line or column, the bad value, and what to do about it.
"""

from __future__ import annotations

import os
from pathlib import Path


class Colregs9Error(Exception):
    """Base class for every error caused by the user's input or environment."""

    exit_code = 1


class InputFileError(Colregs9Error):
    """An input file is missing, empty, truncated, undecodable or of an unknown layout."""

    exit_code = 2


class QueryError(Colregs9Error):
    """A query or scenario TOML file is malformed or has invalid values."""

    exit_code = 2


class ParameterError(Colregs9Error):
    """A parameter (from the CLI or a TOML table) is out of range."""

    exit_code = 2


class ChartError(Colregs9Error):
    """A chart cannot be read or holds no usable depth information."""

    exit_code = 2


class OutputError(Colregs9Error):
    """The output location cannot take the report (a file, a foreign directory, no access)."""

    exit_code = 2


class NoDataError(Colregs9Error):
    """The input is valid but the query selects nothing to work on."""

    exit_code = 3


def input_status(path: Path) -> os.stat_result:
    """``path.stat()`` of an input the user named, its failures one ``InputFileError``: a
    missing file, or one that cannot be reached (a symbolic link that loops, a name too long,
    a file on the way)."""
    try:
        return path.stat()
    except FileNotFoundError:
        raise InputFileError(f"{path}: no such file; check the path") from None
    except OSError as exc:
        raise InputFileError(
            f"{path}: cannot open it ({exc.strerror}); check the path and its symbolic links"
        ) from None
