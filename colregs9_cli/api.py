"""A small Python API for notebooks: the command line's work, in memory.

    import colregs9_cli.api as colregs9

    positions = colregs9.read_ais(["aisdk-2024-09-09.csv"])          # canonical DataFrame
    table = colregs9.vessel_stats(["aisdk-2024-09-09.csv"])           # the stats table
    result = colregs9.replay(["day.nmea.gz"], charts=["cell.000"])    # nothing written
    result.pairs, result.encounters, result.tracks                     # DataFrames

Paths may be strings, and one path may be given alone. Errors are ``Colregs9Error`` (here,
and its subclasses) with the message the command line prints. Importing this module changes
nothing in the process: no matplotlib backend, no signal handler (those are the console
script's, ``cli.run``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .ais.load import count_ais, load_ais
from .core.dimensions import GroupBy, Per, dimension_stats
from .core.replay_results import ReplayResult
from .errors import (
    ChartError,
    Colregs9Error,
    InputFileError,
    NoDataError,
    OutputError,
    ParameterError,
    QueryError,
)
from .jobs.replay import run_replay
from .query import everything_query, load_query

__all__ = [
    "ChartError",
    "Colregs9Error",
    "InputFileError",
    "NoDataError",
    "OutputError",
    "ParameterError",
    "QueryError",
    "Replay",
    "read_ais",
    "replay",
    "vessel_stats",
]

PathLike = str | Path


def _paths(paths: PathLike | Sequence[PathLike]) -> list[Path]:
    """One path or several, as paths (a string is one path, not a sequence of letters)."""
    return [Path(paths)] if isinstance(paths, str | Path) else [Path(p) for p in paths]


def _mmsis(own_mmsi: int | Sequence[int]) -> list[int]:
    """One own-ship MMSI or several, as integers; anything else is a ``ParameterError``."""
    try:
        given = [own_mmsi] if isinstance(own_mmsi, int | str) else list(own_mmsi)
        return [int(m) for m in given]
    except (TypeError, ValueError):
        raise ParameterError(
            f"own_mmsi = {own_mmsi!r}: give an MMSI (9 digits) or a list of them"
        ) from None


def read_ais(paths: PathLike | Sequence[PathLike], query: PathLike | None = None) -> pd.DataFrame:
    """Cleaned positions in the canonical schema, selected by the query (a TOML file)."""
    selected = load_query(Path(query)) if query is not None else everything_query()
    return load_ais(_paths(paths), query=selected).positions


def vessel_stats(
    paths: PathLike | Sequence[PathLike],
    query: PathLike | None = None,
    per: str = "vessel",
    by: str | None = None,
) -> pd.DataFrame:
    """The dimension statistics table of ``colregs9 stats``, without writing its files."""
    selected = load_query(Path(query)) if query is not None else everything_query()
    try:
        per_choice, by_choice = Per(per), None if by is None else GroupBy(by)
    except ValueError as exc:
        raise ParameterError(
            f"{exc}; per is one of {[p.value for p in Per]}, by one of "
            f"{[b.value for b in GroupBy]} or None"
        ) from None
    data = count_ais(_paths(paths), query=selected)
    return dimension_stats(
        data.position_counts, data.dimension_reports, per=per_choice, by=by_choice
    ).to_frame()


@dataclass(frozen=True, eq=False)
class Replay:
    """A replay's tables as DataFrames, and the whole result.

    ``pairs`` and ``encounters`` have the columns of pairs.csv and encounters.csv, typed
    (enums as their text, times as UTC timestamps, nullable integers and booleans);
    ``tracks`` has both vessels' tracks of every encounter, a row per time step:
    ``encounter_id``, ``pair_id``, ``vessel`` (``own``/``target``), ``mmsi``,
    ``timestamp`` (UTC), ``lat_deg``, ``lon_deg``, ``north_m``, ``east_m`` (in the run's
    frame, ``result.frame``, but for a pair beyond its reach: ``EncounterOutcome``).
    ``text`` is what the command prints; ``result`` holds the rest (counts, run.json's
    manifest, each seat's series and figure data).
    """

    pairs: pd.DataFrame
    encounters: pd.DataFrame
    tracks: pd.DataFrame
    text: str
    result: ReplayResult

    @classmethod
    def of(cls, result: ReplayResult) -> Replay:
        """The tables of a ``ReplayResult`` (of this API, or of ``jobs.replay.run_replay``)."""
        return cls(
            pairs=result.pairs_table,
            encounters=result.encounters_table,
            tracks=result.tracks_table,
            text=result.text,
            result=result,
        )

    def series(self, encounter_id: str) -> pd.DataFrame:
        """The time series of one encounter, as its CSV under encounters/ holds it."""
        for seat in self.result.encounters:
            if seat.summary.encounter_id == encounter_id:
                return seat.series
        raise ParameterError(
            f"encounter_id {encounter_id!r}: no such encounter; the encounters table's "
            "encounter_id column lists them"
        )


def replay(
    paths: PathLike | Sequence[PathLike],
    charts: PathLike | Sequence[PathLike] = (),
    query: PathLike | None = None,
    own_mmsi: int | Sequence[int] = (),
) -> Replay:
    """The replay of ``colregs9 replay``, in memory (nothing is written): its pairs,
    encounters and tracks as DataFrames (``Replay``)."""
    return Replay.of(
        run_replay(
            _paths(paths),
            chart_paths=_paths(charts),
            query_path=None if query is None else Path(query),
            own_mmsi=_mmsis(own_mmsi),
            plots=False,
            write=False,
        )
    )
