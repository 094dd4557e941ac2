"""A small Python API for notebooks: the command line's work, in memory.

    import colregs9_cli.api as colregs9

    positions = colregs9.read_ais(["aisdk-2024-09-09.csv"])          # canonical DataFrame
    table = colregs9.vessel_stats(["aisdk-2024-09-09.csv"])           # the stats table
    result = colregs9.replay(["day.nmea.gz"], charts=["cell.000"])    # nothing written
    result.pairs[0].summary                                           # a pair's verdict

Paths may be strings. Errors are ``colregs9_cli.errors.Colregs9Error`` subclasses with the
message the command line prints.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import pandas as pd

from .ais.load import count_ais, load_ais
from .core.dimensions import GroupBy, Per, dimension_stats
from .core.replay_results import ReplayResult
from .errors import ParameterError
from .jobs.replay import run_replay
from .query import everything_query, load_query

PathLike = str | Path


def read_ais(paths: Sequence[PathLike], query: PathLike | None = None) -> pd.DataFrame:
    """Cleaned positions in the canonical schema, selected by the query (a TOML file)."""
    selected = load_query(Path(query)) if query is not None else everything_query()
    return load_ais([Path(p) for p in paths], query=selected).positions


def vessel_stats(
    paths: Sequence[PathLike],
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
    data = count_ais([Path(p) for p in paths], query=selected)
    return dimension_stats(
        data.position_counts, data.dimension_reports, per=per_choice, by=by_choice
    ).to_frame()


def replay(
    paths: Sequence[PathLike],
    charts: Sequence[PathLike] = (),
    query: PathLike | None = None,
    own_mmsi: Sequence[int] = (),
) -> ReplayResult:
    """The replay of ``colregs9 replay``, in memory: pairs, seats, series, verdicts."""
    return run_replay(
        [Path(p) for p in paths],
        chart_paths=[Path(c) for c in charts],
        query_path=None if query is None else Path(query),
        own_mmsi=own_mmsi,
        plots=False,
        write=False,
    )
