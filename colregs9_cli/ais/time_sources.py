"""Where the time of an NMEA message comes from, and the query's ``[ingest]`` table that
orders them (see nmea.py). Apart from the reader, so that a run that reads no NMEA does
not import pyais to check a query."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import TYPE_CHECKING

from ..errors import ParameterError

if TYPE_CHECKING:
    from ..query import Query


class TimeSource(StrEnum):
    """Where a message's time came from (nmea.py's docstring)."""

    TAG_BLOCK = "tag_block"
    PGHP = "pghp"
    ARRIVAL = "arrival"


DEFAULT_TIME_SOURCES: tuple[TimeSource, ...] = (
    TimeSource.TAG_BLOCK,
    TimeSource.PGHP,
    TimeSource.ARRIVAL,
)


@dataclass(frozen=True)
class IngestParams:
    """The ``[ingest]`` table of a query: how raw NMEA is read.

    - ``nmea_time_sources``: the time sources to use, in order of precedence (nmea.py's
      docstring); the default puts the observation (``tag_block``, ``pghp``) before the
      ``arrival`` at the archive.
    """

    nmea_time_sources: tuple[TimeSource, ...] = DEFAULT_TIME_SOURCES

    def __post_init__(self) -> None:
        names = [str(s) for s in self.nmea_time_sources]
        allowed = [s.value for s in TimeSource]
        bad = [n for n in names if n not in allowed]
        if not names or bad or len(set(names)) != len(names):
            raise ParameterError(
                f"[ingest] nmea_time_sources = {names!r}: give each of {', '.join(allowed)} "
                "at most once, at least one, in order of precedence"
            )
        object.__setattr__(self, "nmea_time_sources", tuple(TimeSource(n) for n in names))


def ingest_params(query: Query) -> IngestParams:
    """The query's ``[ingest]`` table, checked (``ParameterError`` naming the file)."""
    from ..config import dataclass_from_table

    where = f"{query.source if query.source is not None else 'query'} [ingest]"
    return dataclass_from_table(IngestParams, dict(query.tables.get("ingest", {})), where)
