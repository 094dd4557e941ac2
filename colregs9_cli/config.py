"""Typed parameters: frozen dataclasses filled from TOML tables with strict key checking.

Each core module owns its parameter dataclass (``ManoeuvrabilityParams`` in
``manoeuvrability.py``, ``ColregsParams`` in ``colregs.py``, ...). This module turns a TOML
table into one of them, rejecting unknown keys and wrong types with a message that names the
file, the table and the key.
"""

from __future__ import annotations

import dataclasses
import stat
import tomllib
import types
import typing
from pathlib import Path
from typing import Any, TypeVar

from .errors import InputFileError, ParameterError, QueryError, input_status

T = TypeVar("T")
# tomllib parses nested arrays and inline tables recursively, so hundreds of levels exhaust
# Python's stack; no file colregs9 reads nests them more than 2 deep (a scenario's route).
TOO_DEEP = (
    "arrays or inline tables nested hundreds of levels deep, too deep to read (colregs9's "
    "files nest them 2 deep at most)"
)


def read_toml(path: Path) -> dict[str, Any]:
    """Read a TOML file; a missing file or a syntax error becomes one clear error."""
    status = input_status(path)
    if stat.S_ISDIR(status.st_mode):
        raise InputFileError(f"{path}: a directory, not a file; give the TOML file")
    if not stat.S_ISREG(status.st_mode):  # reading a pipe would wait for a writer
        raise InputFileError(f"{path}: a pipe or a device, not a file; give the TOML file")
    try:
        with path.open("rb") as handle:
            return tomllib.load(handle)
    except tomllib.TOMLDecodeError as exc:
        raise QueryError(f"{path}: TOML syntax error: {exc}; fix the file") from None
    except RecursionError:
        raise QueryError(f"{path}: {TOO_DEEP}; fix the file") from None
    except UnicodeDecodeError as exc:
        raise QueryError(f"{path}: not UTF-8 text ({exc.reason}); save it as UTF-8") from None
    except ValueError:  # an integer of more digits than Python converts
        raise QueryError(
            f"{path}: a number of more than 4300 digits; give numbers of a sensible size"
        ) from None


def _accepts(annotation: Any, value: Any) -> bool:
    origin = typing.get_origin(annotation)
    if annotation is typing.Any:
        return True
    if origin in (typing.Union, types.UnionType):
        return any(_accepts(arg, value) for arg in typing.get_args(annotation))
    if origin is typing.Literal:
        return _hashable(value) and value in typing.get_args(annotation)
    if annotation is type(None):
        return value is None
    if annotation is float:
        return isinstance(value, int | float) and not isinstance(value, bool)
    if annotation is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if origin in (tuple, list, frozenset, set):
        if not isinstance(value, list | tuple):
            return False
        arguments = [a for a in typing.get_args(annotation) if a is not Ellipsis]
        item = arguments[0] if len(arguments) == 1 else typing.Any
        return all(_accepts(item, v) and _hashable(v) for v in value)
    if isinstance(annotation, type) and issubclass(annotation, dataclasses.Field):
        return True
    if isinstance(annotation, type):
        if hasattr(annotation, "__members__"):  # an Enum: accept its values
            values = {m.value for m in annotation}  # type: ignore[attr-defined]
            return _hashable(value) and value in values
        return isinstance(value, annotation)
    return True


def _hashable(value: Any) -> bool:
    return not isinstance(value, list | dict)


def _expected(annotation: Any) -> str:
    """What a key of this type takes, for messages: "a number", "one of 'a', 'b'", ..."""
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        parts = [_expected(a) for a in typing.get_args(annotation) if a is not type(None)]
        return " or ".join(parts)
    if origin is typing.Literal:
        return "one of " + ", ".join(repr(a) for a in typing.get_args(annotation))
    if annotation is float:
        return "a number"
    if annotation is int:
        return "an integer"
    if annotation is str:
        return "a string"
    if annotation is bool:
        return "true or false"
    if origin in (tuple, list, frozenset, set):
        arguments = [a for a in typing.get_args(annotation) if a is not Ellipsis]
        item = _expected(arguments[0]) if len(arguments) == 1 else "a value"
        return f"a flat list, each item {item}"
    if isinstance(annotation, type) and hasattr(annotation, "__members__"):
        values = [repr(m.value) for m in annotation]  # type: ignore[attr-defined]
        return "one of " + ", ".join(values)
    return f"a {getattr(annotation, '__name__', annotation)}"


def _convert(annotation: Any, value: Any) -> Any:
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        for arg in typing.get_args(annotation):
            if arg is not type(None) and _accepts(arg, value):
                return _convert(arg, value)
        return value
    if annotation is float:
        return float(value)
    if origin is tuple:
        return tuple(value)
    if origin is frozenset:
        return frozenset(value)
    if isinstance(annotation, type) and hasattr(annotation, "__members__"):
        return annotation(value)
    return value


def _shown(value: Any, limit: int = 80) -> str:
    """``repr(value)`` cut to one short line."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def dataclass_from_table(cls: type[T], table: dict[str, Any], where: str) -> T:
    """Build the frozen dataclass ``cls`` from a TOML table, defaults for absent keys.

    ``where`` names the place for messages, e.g. ``"queries/q.toml [manoeuvrability]"``.
    Validation of ranges stays in the dataclass's own ``__post_init__``.
    """
    if not isinstance(table, dict):
        raise QueryError(f"{where}: expected a table, got {table!r}")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}  # type: ignore[arg-type]
    unknown = sorted(set(table) - set(fields))
    if unknown:
        raise QueryError(
            f"{where}: unknown key {unknown[0]!r}; allowed keys are {', '.join(sorted(fields))}"
        )
    values: dict[str, Any] = {}
    for name, value in table.items():
        annotation = hints[name]
        if not _accepts(annotation, value):
            raise QueryError(
                f"{where}: key {name!r} has value {_shown(value)}; give {_expected(annotation)}"
            )
        values[name] = _convert(annotation, value)
    try:
        return cls(**values)
    except (ParameterError, QueryError) as exc:
        # The dataclass checks ranges without knowing the file: name it here.
        message = str(exc)
        file_part = where.split(" [", 1)[0]
        located = f"{file_part} {message}" if message.startswith("[") else f"{where}: {message}"
        raise type(exc)(located) from None
