"""``colregs9 stats``: read the AIS through a query, compute the dimension statistics
(``colregs9_cli.core.dimensions``) and write the reports (``report/stats_report.py``).

The first input starts being read before pandas and matplotlib are imported: their import
keeps one core busy for a good while, and the CSV parse takes the other meanwhile
(``ais.csv_read.start_reading``; figures: tests/benchmarks/README.md). So this module
imports them, and everything else the reading does not need (shapely, ``pyarrow.compute``),
only inside ``run_stats``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from ..ais.csv_read import start_reading
from ..errors import ParameterError

if TYPE_CHECKING:
    from ..core.dimensions import GroupBy, Per, StatsResult

E = TypeVar("E", bound=StrEnum)


@dataclass(frozen=True)
class StatsRun:
    """What ``colregs9 stats`` produced: the result, the text table and the files written."""

    result: StatsResult
    text: str
    out_dir: Path
    files: tuple[Path, ...]
    manifest: dict[str, Any]


def default_out_dir(query_name: str) -> Path:
    return Path("reports") / f"stats-{query_name}"


def _choice(enum: type[E], value: E | str, option: str) -> E:
    try:
        return enum(value)
    except ValueError:
        allowed = ", ".join(member.value for member in enum)
        raise ParameterError(f"{option} {value!r} is not one of {allowed}") from None


def run_stats(
    paths: Sequence[Path],
    query_path: Path | None = None,
    per: Per | str = "vessel",
    by: GroupBy | str | None = None,
    fmt: str | None = None,
    out_dir: Path | None = None,
    quiet: bool = True,
    overwrite: bool = False,
) -> StatsRun:
    """Read ``paths`` through the query, compute the statistics and write the reports.

    Raises ``NoDataError`` (exit code 3) when the query selects no rows, and the other
    ``Colregs9Error`` subclasses for bad input files, queries or options.
    """
    with start_reading(paths, fmt) as started:
        from ..query import everything_query, load_query

        query = load_query(query_path) if query_path is not None else everything_query()
        if query.has_replay_tables:
            from .replay_params import stage_tables

            stage_tables(query)
        from ..outputs import check_out_dir

        target = Path(out_dir) if out_dir is not None else default_out_dir(query.name)
        given = [*paths, *([query_path] if query_path else [])]
        check_out_dir(target, overwrite, inputs=given, command="stats")
        from ..ais.load import count_ais
        from ..core.dimensions import GroupBy, Per, dimension_stats
        from ..provenance import inputs_manifest
        from ..report.stats_report import (
            StatsInputs,
            build_manifest,
            format_text,
            write_stats_reports,
        )

        per = _choice(Per, per, "--per")
        by = None if by is None else _choice(GroupBy, by, "--by")
        data = count_ais(paths, query=query, fmt=fmt, quiet=quiet, started=started)
    result = dimension_stats(data.position_counts, data.dimension_reports, per=per, by=by)
    read = StatsInputs(
        inputs=inputs_manifest(data.inputs),
        rows_read=data.ledger.rows_read,
        rows_in_query=data.rows_in_query,
        ledger=data.ledger.to_dict(),
    )
    manifest = build_manifest(result, query, read)
    files = write_stats_reports(target, result, query.name, manifest, overwrite)
    return StatsRun(
        result=result,
        text=format_text(result, query.name),
        out_dir=target,
        files=files,
        manifest=manifest,
    )
