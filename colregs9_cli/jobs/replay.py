"""``colregs9 replay``: historical AIS, pair by pair, through G_a and G_d (docs/design.md §5).

The pipeline, slab by slab in time (``replay_input.py`` reads the AIS through the query one
slab at a time, ``slabs.py`` segments and evaluates them): the run's local frame (the
query's region, or the extent of the data when the query has none) → per-vessel tracks
(``tracks.py``; reports dropped as same-second duplicates or speed jumps go into the rejects
ledger) → encounters (``encounters.py``) → for each triggered pair, evaluated once for both seats:

each triggered pair is evaluated once for both seats (``core/pair.py``: G_a, the
manoeuvrability estimates, G_d of both seats, the audit facts) and projected onto its rows
(``core/rows.py``) and seats (``core/replay_results.py``).

Each pair gives one ``PairOutcome`` (pairs.csv) and one ``EncounterOutcome`` per reported
seat (encounters.csv and the per-encounter files); both seats of a pair carry the same
situation, final roles and audit facts.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..ais.inputs import InputFile
from ..ais.ledger import DropReason, RejectReason, RejectsLedger
from ..charts.channels import Channels, load_channels
from ..charts.provenance import charts_manifest
from ..charts.sources import ChartSource, read_charts
from ..charts.water import Chart, project_charts
from ..core.encounters import Encounter, check_own_mmsi
from ..core.pair import PairParams, evaluate_pair
from ..core.replay_results import (
    PairOutcome,
    ReplayCounts,
    ReplayResult,
    pair_outcome,
)
from ..core.rule9 import RULES_APPLIED
from ..core.tracks import REQUIRED_COLUMNS, STATIC_COLUMNS, Tracks, TrackStats, context_s
from ..errors import ChartError, NoDataError, ParameterError
from ..geo import LocalFrame
from ..outputs import check_out_dir
from ..progress import progress_bar, progress_enabled
from ..provenance import inputs_manifest, jsonable, query_manifest, run_header
from ..query import Query, everything_query, load_query
from ..report.replay_geopackage import Domains
from ..report.replay_report import format_summary
from .executor import executor
from .replay_input import open_replay_input, segment_input_part
from .replay_params import ReplayParams, ReplayRunParams, stage_tables
from .slabs import (
    Extent,
    PairEvaluator,
    Segmentation,
    SlabContext,
    SlabResult,
    track_vertices,
)

# The canonical columns a replay reads: those of the reports and the static data.
REPLAY_COLUMNS: tuple[str, ...] = (*REQUIRED_COLUMNS, *STATIC_COLUMNS)


def default_out_dir(query_name: str) -> Path:
    return Path("reports") / f"replay-{query_name}"


def run_params(
    query: Query,
    own_mmsi: Sequence[int] = (),
    overrides: dict[str, dict[str, Any]] | None = None,
) -> ReplayRunParams:
    """The run's parameters: the query's tables, then the CLI overrides (``None`` = not given).

    ``overrides`` maps a table name (``replay``, ``colregs``, ``manoeuvrability``) to the
    values given on the command line; each is validated by its dataclass.
    """
    replay, colregs, manoeuvrability = stage_tables(query)
    given = {
        table: {k: v for k, v in values.items() if v is not None}
        for table, values in (overrides or {}).items()
    }
    replay = dataclasses.replace(replay, **given.get("replay", {}))
    colregs = dataclasses.replace(colregs, **given.get("colregs", {}))
    manoeuvrability = dataclasses.replace(manoeuvrability, **given.get("manoeuvrability", {}))
    return ReplayRunParams(
        replay=replay,
        colregs=colregs,
        manoeuvrability=manoeuvrability,
        own_mmsi=tuple(sorted({int(m) for m in own_mmsi})),
    )


# Charts farther than this from every AIS position are left out of a run (``ChartSource.near``);
# a ship domain reaches a few kilometres at most.
CHART_MARGIN_DEG = 0.25


def run_frame(query: Query, extent: Extent, chart: ChartSource | None = None) -> LocalFrame:
    """A frame centred on the charts, where the manoeuvrability estimate is made; without
    charts, on the query region, else on the data (``slabs.Extent.frame``).

    The frame carries the chart, the manoeuvrability estimate and the figures; the geometry
    between vessels never uses it (``pair_search.py``, ``encounters.py``), and the tracks are
    resampled on the Earth, so a position beyond its reach only loses its frame coordinates.
    The charts come first because a national query's centre may lie hundreds of kilometres
    from a harbour cell, where the frame's scale would bend the ship domains.
    """
    if chart is not None:
        return LocalFrame.centred_on(*chart.bounds_wgs84())
    frame = query.frame()
    if frame is not None:
        return frame
    return extent.frame()


def _ledger_with_tracks(ledger: RejectsLedger, stats: TrackStats) -> RejectsLedger:
    """The loader's ledger plus the reports that segmentation dropped, and the SOGs it set
    to null (their reports are used)."""
    result = copy.deepcopy(ledger)
    dropped = stats.same_time_dropped + stats.speed_jump_dropped
    result.rows_used -= dropped
    result.reject(RejectReason.DUPLICATE, stats.same_time_dropped)
    result.reject(RejectReason.SPEED_JUMP, stats.speed_jump_dropped)
    result.drop(DropReason.SOG_CONTRADICTED, stats.sog_contradicted)
    return result


def _counts(segmentation: Segmentation, results: Sequence[SlabResult]) -> ReplayCounts:
    return ReplayCounts(
        vessels=len(segmentation.vessels),
        segments=segmentation.stats.segments,
        candidate_pair_steps=sum(r.candidate_pair_steps for r in results),
        candidate_pairs=len(frozenset().union(*(r.candidate_pairs for r in results))),
        encounters=sum(r.encounters for r in results),
        triggered=sum(r.triggered for r in results),
        triggered_pairs=sum(len(r.pairs) for r in results),
    )


def _no_overlap(chart_paths: Sequence[Path], positions: pd.DataFrame) -> ChartError:
    names = ", ".join(str(p) for p in chart_paths)
    return ChartError(
        f"{names}: the chart does not cover any of the AIS positions (lat "
        f"{positions['lat_deg'].min():.4f}–{positions['lat_deg'].max():.4f}, lon "
        f"{positions['lon_deg'].min():.4f}–{positions['lon_deg'].max():.4f}); give a chart "
        "of the area the AIS covers, or leave out --chart"
    )


def load_run_chart(
    source: ChartSource, chart_paths: Sequence[Path], frame: LocalFrame, positions: pd.DataFrame
) -> Chart:
    """The charts read (``charts.sources.read_charts``) in the run's frame; a chart that covers
    none of the AIS is an error.

    The boxes are compared first, so that a chart far away is never projected into the frame.
    """
    lat_min, lat_max, lon_min, lon_max = source.bounds_wgs84()
    lat = positions["lat_deg"].to_numpy(dtype=float)
    lon = positions["lon_deg"].to_numpy(dtype=float)
    in_box = (lat >= lat_min) & (lat <= lat_max) & (lon >= lon_min) & (lon <= lon_max)
    if not in_box.any():
        raise _no_overlap(chart_paths, positions)
    chart = project_charts(source, frame)
    north_m, east_m = frame.to_local(lat[in_box], lon[in_box])
    if not chart.covers(north_m, east_m).any():
        raise _no_overlap(chart_paths, positions)
    return chart


def build_manifest(
    query: Query,
    inputs: Sequence[InputFile],
    ledger: RejectsLedger,
    chart: Chart | None,
    chart_paths: Sequence[Path],
    frame: LocalFrame,
    params: ReplayRunParams,
    track_stats: TrackStats,
    counts: ReplayCounts,
    pairs: tuple[PairOutcome, ...],
    accept_chart_gaps: bool = False,
) -> dict[str, Any]:
    """The content of run.json."""
    return {
        **run_header("replay"),
        "query": query_manifest(query),
        "frame": {"lat0_deg": frame.lat0_deg, "lon0_deg": frame.lon0_deg},
        "parameters": jsonable(params),
        "inputs": inputs_manifest(inputs),
        "charts": charts_manifest(chart_paths, chart.detail_order if chart is not None else ()),
        "accept_chart_gaps": accept_chart_gaps,
        "chart_cells": [jsonable(cell) for cell in (chart.cells if chart is not None else ())],
        "ledger": ledger.to_dict(),
        "ledger_balanced": ledger.balanced,
        "tracks": jsonable(track_stats),
        "counts": jsonable(counts),
        "verdicts": verdict_counts(pairs),
        "rules_applied": RULES_APPLIED,
    }


def run_replay(
    ais_paths: Sequence[Path],
    chart_paths: Sequence[Path] = (),
    query_path: Path | None = None,
    own_mmsi: Sequence[int] = (),
    out_dir: Path | None = None,
    plots: bool = True,
    overrides: dict[str, dict[str, Any]] | None = None,
    fmt: str | None = None,
    quiet: bool = True,
    overwrite: bool = False,
    accept_chart_gaps: bool = False,
    write: bool = True,
    workers: int = 1,
    scheduler: str | None = None,
    scratch_dir: Path | None = None,
    domains: Domains | str = Domains.RESTRICTED,
    vessel_tracks: bool = True,
) -> ReplayResult:
    """Replay ``ais_paths`` and write the reports (see the module docstring); with
    ``write=False`` nothing is written (the result is in memory only). ``domains``: which
    ship-domain ellipses report.gpkg holds (all, restricted or none; recorded in run.json);
    ``vessel_tracks``: whether it holds every vessel's track (recorded too; without, the
    spill is not read for them).

    Errors: an own MMSI not in the data, fewer than two vessels (``NoDataError``, exit 3); a
    chart that covers none of the AIS (``ChartError``, exit 2); bad files or parameters. A run
    without triggered encounters is not an error: it writes a header-only encounters.csv.

    The run works through time in slabs (``slabs.py``, ``[replay] slab_s``), spilling the
    decided reports to a scratch directory in ``scratch_dir`` (default: the system's
    temporary directory). ``workers`` > 1 runs the slabs on a local Dask cluster of that many
    processes, ``scheduler`` on the Dask cluster at that address (``executor.py``).
    """
    domains = _checked_options(workers, scratch_dir, domains)
    with executor(workers, scheduler, scratch_dir) as runner:
        query = load_query(query_path) if query_path is not None else everything_query()
        params = run_params(query, own_mmsi, overrides)
        target = Path(out_dir) if out_dir is not None else default_out_dir(query.name)
        if write:
            given = [*ais_paths, *chart_paths, *([query_path] if query_path else [])]
            check_out_dir(target, overwrite, inputs=given, command="replay")
        with _scratch_directory(scratch_dir) as scratch:
            spill_dir = Path(scratch) / "spill"
            spill_dir.mkdir()
            ais = open_replay_input(
                ais_paths, query, fmt, quiet, Path(scratch), params.replay.slab_s, REPLAY_COLUMNS
            )
            # Stage 1 in parts of the vessels, one per worker on a cluster (the results do not
            # depend on their number); the bar counts the slabs of one part, else the parts.
            parts = ais.parts(runner.parts())
            unit, units = ("slabs", len(ais.slabs)) if len(parts) == 1 else ("parts", len(parts))
            with progress_bar(f"Tracks ({unit})", units, progress_enabled(quiet)) as bar:
                tasks = [
                    functools.partial(segment_input_part, part, k, spill_dir, params.replay)
                    for k, part in enumerate(parts)
                ]
                segmentation = ais.merge(runner.segment(tasks, bar))
            ais.check_positions()
            if len(ais.vessels) < 2:
                raise NoDataError(
                    f"{', '.join(str(p) for p in ais_paths)}: the AIS selected by query "
                    f"'{query.name}' holds {len(ais.vessels)} vessel(s); an encounter needs "
                    "two. Widen the query or give more AIS"
                )
            source = _charts_near(chart_paths, accept_chart_gaps, segmentation)
            check_own_mmsi(params.own_mmsi, segmentation.vessels)
            frame = run_frame(query, segmentation.extent, source)
            chart: Chart | None = None
            if source is not None:
                chart = load_run_chart(source, chart_paths, frame, segmentation.points)
            slabs = slab_range(segmentation, params.replay)
            with progress_bar(
                "Pairs and verdicts (slabs)", len(slabs), progress_enabled(quiet)
            ) as bar:
                results = runner.replay_slabs(
                    slabs,
                    slab_context(segmentation, frame, params),
                    _pair_evaluator(params.pair, chart),
                    chart,
                    bar,
                )
            tracks = _vessel_tracks(segmentation, vessel_tracks)  # before the spill goes
        counts = _counts(segmentation, results)
        outcomes = tuple(pair for result in results for pair in result.pairs)
        manifest = build_manifest(
            query,
            ais.inputs,
            _ledger_with_tracks(ais.ledger, segmentation.stats),
            chart,
            chart_paths,
            frame,
            params,
            dataclasses.replace(segmentation.stats, samples=sum(r.samples for r in results)),
            counts,
            outcomes,
            accept_chart_gaps,
        )
        manifest["parameters"].update(domains=domains.value, vessel_tracks=vessel_tracks)
        manifest["slabs"] = _slab_facts(params.replay.slab_s, len(slabs), workers, scheduler)
        manifest["slabs"]["pairs_followed_past_their_slab"] = sum(r.followed for r in results)
        result = ReplayResult(
            query_name=query.name,
            out_dir=target,
            frame=frame,
            params=params.pair,
            pairs=outcomes,
            counts=counts,
            manifest=manifest,
            files=(),
            vessel_tracks=tracks,
        )
        if not write:
            return dataclasses.replace(result, text=format_summary(result))
        with progress_bar("Reports", len(result.encounters), progress_enabled(quiet)) as bar:
            files = runner.write_reports(result, chart, plots, bar, overwrite, domains)
        return dataclasses.replace(result, files=files, text=format_summary(result))


def _slab_facts(slab_s: float, slabs: int, workers: int, scheduler: str | None) -> dict[str, Any]:
    """run.json's ``slabs``: their length and number, and the workers (the local count, or
    the scheduler's address)."""
    where = workers if scheduler is None else f"scheduler {scheduler}"
    return {"slab_s": slab_s, "slabs": slabs, "workers": where}


def _checked_options(workers: int, scratch_dir: Path | None, domains: Domains | str) -> Domains:
    """The options checked before any work; ``domains`` as a ``Domains``."""
    if workers < 1:
        raise ParameterError(f"--workers {workers}: give 1 or more worker processes")
    if scratch_dir is not None and not Path(scratch_dir).is_dir():
        raise ParameterError(
            f"--scratch {scratch_dir}: not a directory; give an existing directory (on a "
            "multi-machine cluster, one that every worker mounts)"
        )
    return domains_choice(domains)


def domains_choice(value: Domains | str) -> Domains:
    """``--domains`` as a ``Domains``; another value is a ``ParameterError``."""
    try:
        return Domains(value)
    except ValueError:
        choices = ", ".join(d.value for d in Domains)
        raise ParameterError(f"--domains {value!r} is not one of {choices}") from None


def _vessel_tracks(segmentation: Segmentation, wanted: bool) -> pd.DataFrame:
    """Every vessel's track (``slabs.track_vertices``) with her name, ship type and length
    from her static reports, as categories: a few bytes a vertex; none unless ``wanted``."""
    spill = segmentation.spill if wanted else dataclasses.replace(segmentation.spill, files=())
    vertices = track_vertices(spill)
    mmsi = vertices["mmsi"].to_numpy()
    new_vessel = np.diff(mmsi, prepend=-1) != 0
    # Per vessel, then spread by code: the static table spread over millions of vertices
    # would take gigabytes.
    vessel = np.cumsum(new_vessel) - 1
    statics = segmentation.statics.reindex(mmsi[new_vessel])
    for name in ("name", "ship_type", "length_m"):
        values = statics[name] if name in statics.columns else pd.Series(index=statics.index)
        per_vessel = pd.Categorical(values.to_numpy())
        vertices[name] = pd.Categorical.from_codes(
            per_vessel.codes[vessel], categories=per_vessel.categories
        )
    return vertices


def _charts_near(
    chart_paths: Sequence[Path], accept_chart_gaps: bool, segmentation: Segmentation
) -> ChartSource | None:
    """The charts given, those within ``CHART_MARGIN_DEG`` of the AIS where any are (none
    near: ``load_run_chart`` says so)."""
    if not chart_paths:
        return None
    source = read_charts(chart_paths, accept_chart_gaps)
    points = segmentation.points
    near = source.near(points["lat_deg"], points["lon_deg"], CHART_MARGIN_DEG)
    return near if near.paths else source


@contextmanager
def _scratch_directory(parent: Path | None) -> Iterator[str]:
    """A temporary directory for the spilled reports, in ``parent`` (default: the system's)."""
    try:
        scratch = tempfile.TemporaryDirectory(prefix="colregs9-slabs-", dir=parent)
    except OSError as exc:
        where = f"--scratch {parent}" if parent is not None else "the temporary directory"
        raise ParameterError(
            f"{where}: cannot make a scratch directory there ({exc.strerror}); give a "
            "writable directory with --scratch"
        ) from None
    with scratch as path:
        yield path


def _pair_evaluator(params: PairParams, chart: Chart | None) -> PairEvaluator:
    """``_evaluate`` with the run's parameters and the chart's channels, these without the
    chart they were read from (the pairs' facts need no navigable width), so that a task
    carries kilobytes, not the chart again."""
    channels = None if chart is None else dataclasses.replace(load_channels(chart), chart=None)
    return functools.partial(_evaluate, params=params, channels=channels)


def _evaluate(
    tracks: Tracks,
    encounter: Encounter,
    seats: tuple[int, ...],
    chart: Chart | None,
    params: PairParams,
    channels: Channels | None,
) -> PairOutcome:
    """One triggered pair's outcome: evaluated once, then projected onto its reported seats."""
    evaluation = evaluate_pair(tracks, encounter, chart, params, channels)
    return pair_outcome(evaluation, seats, tracks.frame)


def slab_range(segmentation: Segmentation, params: ReplayParams) -> list[int]:
    """The slabs whose core the decided reports reach, with the context resampling needs
    around them (``tracks.context_s``): a slab far from any report can start no encounter,
    so a gap of months in the data costs nothing."""
    slab_s = params.slab_s
    margin_s = context_s(params.tracks)
    first = math.floor(segmentation.first_s / slab_s) if segmentation.spill.files else 0
    last = math.floor(segmentation.last_s / slab_s) if segmentation.spill.files else -1
    slabs: set[int] = set()
    for spilled in segmentation.spill.files:
        low = max(first, math.floor((spilled.t_min_s - margin_s) / slab_s))
        high = min(last, math.floor((spilled.t_max_s + margin_s) / slab_s))
        slabs.update(range(low, high + 1))
    return sorted(slabs)


def slab_context(
    segmentation: Segmentation, frame: LocalFrame, params: ReplayRunParams
) -> SlabContext:
    return SlabContext(
        spill=segmentation.spill,
        statics=segmentation.statics,
        frame=frame,
        params=params.replay,
        course_source=params.colregs.course_source,
        own_mmsi=params.own_mmsi,
        data_end_s=segmentation.last_s,
    )


def verdict_counts(pairs: Sequence[PairOutcome]) -> dict[str, Any]:
    """The pairs counted for run.json: by interaction, and the encounters' verdicts by
    situation, deciding rule and audit fact."""

    def count(values: Sequence[Any]) -> dict[str, int]:
        texts = ["" if v is None else str(getattr(v, "value", v)).lower() for v in values]
        return {key: texts.count(key) for key in sorted(set(texts))}

    summaries = [p.summary for p in pairs]
    encounters = [s for s in summaries if s.situation is not None]
    return {
        "pairs": len(summaries),
        "interaction": count([s.interaction for s in summaries]),
        "encounters": len(encounters),
        "situation": count([s.situation for s in encounters]),
        "situation_ambiguous": sum(bool(s.situation_ambiguous) for s in encounters),
        "deciding_rule": count([s.deciding_rule for s in encounters]),
        "rule9_applied": sum(bool(s.rule9_applied) for s in encounters),
        "both_restricted": sum(bool(s.both_restricted) for s in encounters),
        "verdict_rests_on_defaults": sum(bool(s.verdict_rests_on_defaults) for s in encounters),
        "data_covers_cpa": sum(s.data_covers_cpa for s in summaries),
        "give_way_vessel_acted": count([s.give_way_vessel_acted for s in encounters]),
        "give_way_action_as_rule_asks": count([s.give_way_action_as_rule_asks for s in encounters]),
        "passed_port_to_port": count([s.passed_port_to_port for s in encounters]),
        "estimated_restricted": count(
            [e for s in encounters for e in (s.estimated_restricted_a, s.estimated_restricted_b)]
        ),
    }
