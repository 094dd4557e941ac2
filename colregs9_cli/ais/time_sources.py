"""Where the time of an NMEA message comes from, and the query's ``[ingest]`` table that
orders them (see nmea.py). Apart from the reader, so that a run that reads no NMEA does
not import pyais to check a query."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from ..errors import ParameterError


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
