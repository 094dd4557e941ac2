"""The parts every run.json shares: tool and version, the query, the inputs, JSON values.

Each chart's files and hashes are ``charts.provenance.charts_manifest``."""

from __future__ import annotations

import dataclasses
import hashlib
import math
import sys
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import pandas as pd

from . import __version__

if TYPE_CHECKING:
    from .query import Query


class InputRecord(Protocol):
    """One input of a run as run.json records it (``ais.inputs.InputFile`` is one)."""

    @property
    def path(self) -> Path: ...
    @property
    def sha256(self) -> str: ...
    @property
    def layout(self) -> str: ...
    @property
    def rows_read(self) -> int: ...
    @property
    def dataset(self) -> Path | None: ...
    @property
    def ingest_query(self) -> Mapping[str, Any] | None: ...


def jsonable(value: Any) -> Any:
    """Parameters and inputs (dataclasses, enums, paths, times, sets, geometries) as JSON."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: jsonable(getattr(value, f.name)) for f in dataclasses.fields(value) if f.repr
        }
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, set | frozenset):
        return sorted((jsonable(v) for v in value), key=str)
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, datetime | pd.Timestamp):
        return value.isoformat()
    if isinstance(value, float) and math.isnan(value):
        return None
    if value is None or isinstance(value, str | int | float | bool):
        return value
    if hasattr(value, "wkt"):
        return value.wkt
    if hasattr(value, "item"):  # numpy scalars
        return jsonable(value.item())
    return str(value)


def run_header(command: str) -> dict[str, Any]:
    return {
        "tool": "colregs9",
        "version": __version__,
        "command": command,
        "argv": list(sys.argv),
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def file_sha256(path: Path) -> str:
    """The sha256 of a file's bytes, in hex."""
    with path.open("rb") as handle:
        return hashlib.file_digest(handle, "sha256").hexdigest()


def query_manifest(query: Query) -> dict[str, Any]:
    return {
        "name": query.name,
        "description": query.description,
        "source": None if query.source is None else str(query.source),
        "region": jsonable(query.region),
        "time": jsonable(query.time),
        "vessels": jsonable(query.vessels),
    }


def inputs_manifest(inputs: Sequence[InputRecord]) -> list[dict[str, Any]]:
    """Each input file; one read from a dataset (``colregs9 ingest``) names it too, with the
    query it was ingested through."""
    return [
        {
            "path": str(item.path),
            "sha256": item.sha256,
            "layout": item.layout,
            "rows_read": item.rows_read,
            **(
                {"dataset": str(item.dataset), "ingest_query": jsonable(item.ingest_query)}
                if item.dataset is not None
                else {}
            ),
        }
        for item in inputs
    ]
