"""``colregs9 replay``: historical AIS, encounter by encounter, through G_a and G_d (DESIGN §5).

The pipeline: read the AIS through the query → the run's local frame (the query's region, or
the extent of the data when the query has none) → per-vessel tracks (``tracks.py``; reports
dropped as same-second duplicates or speed jumps go into the rejects ledger) → encounters
(``encounters.py``) → for each triggered encounter, from the trigger until the pair passes
(TCPA < 0) or the encounter ends, the COLREGs evaluation G_a (``colregs.py``) and the rule 9
automaton G_d (``rule9.py``) at every step. The encounter's verdict is the one at the
trigger step; the later steps are its time series.

Manoeuvrability (event d3) is estimated for the target with her length, breadth and draught.
A missing dimension takes the ``[replay]`` default, the mean of the paper's Table 1, and the
encounter is flagged ``target_dimensions_defaulted``. No chart, or a target outside
the chart's coverage, gives ``unknown``: ¬d3 for the automaton, recorded as ``unknown``.

The estimate is made at the trigger step (always: it is the verdict and the figure), and at a
later step only when G_d reaches D3 there (own ship stand-on, the target not reporting a
restricted status) and the last estimate is at least ``reassess_every_s`` old; otherwise the
last estimate is carried forward. Every step of the time series says which step its estimate
was computed at (``restricted_assessed_utc``).

Audit columns beyond the paper: ``actual_min_separation_m`` is the least range between the
two resampled tracks over the whole encounter; ``give_way_vessel_acted`` says whether every
vessel that should give way after rule 9 changed course by at least ``course_change_deg`` or
speed by at least ``speed_change_frac`` (of her speed at the trigger) at some step between
the trigger and the actual closest approach after it. It is empty when no vessel gives way.
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .ais.ledger import RejectReason, RejectsLedger
from .ais.load import AisData, load_ais
from .chart import Chart, project_charts, read_charts
from .colregs import (
    ColregsParams,
    Kinematics,
    Role,
    Situation,
    colregs_params_from_table,
    evaluate_colregs,
)
from .encounters import Encounter, EncounterSearch, encounter_series, find_encounters, velocity_mps
from .errors import ChartError, NoDataError
from .geo import LocalFrame
from .manoeuvrability import (
    ManoeuvrabilityAssessment,
    ManoeuvrabilityParams,
    Restriction,
    assess_manoeuvrability,
)
from .progress import progress_bar, progress_enabled
from .query import Query, everything_query, load_query
from .replay_params import ReplayParams, TargetDimensions, replay_params_from_table
from .report.manifest import inputs_manifest, jsonable, query_manifest, run_header
from .report.replay_report import format_summary, write_replay_reports
from .rule9 import Rule9Assessment, assess_rule9
from .tracks import Tracks, build_tracks
from .units import signed_angle_deg


@dataclass(frozen=True)
class ReplayRunParams:
    """Every parameter of one replay run, as written to run.json."""

    replay: ReplayParams
    colregs: ColregsParams
    manoeuvrability: ManoeuvrabilityParams
    own_mmsi: tuple[int, ...]


@dataclass(frozen=True)
class EncounterSummary:
    """One row of encounters.csv; the field order is the column order."""

    encounter_id: str
    own_mmsi: int
    target_mmsi: int
    own_name: str | None
    target_name: str | None
    start_utc: pd.Timestamp
    trigger_utc: pd.Timestamp
    end_utc: pd.Timestamp
    situation: Situation
    own_role_colregs: Role
    target_role_colregs: Role
    target_nav_status: int | None
    target_reports_restricted: bool
    target_estimated_restricted: Restriction
    rule9_applied: bool
    own_role_final: Role
    automaton_path: str
    range_m_at_trigger: float
    cpa_m: float
    tcpa_s: float
    actual_min_separation_m: float
    actual_min_separation_utc: pd.Timestamp
    give_way_vessel: str
    give_way_vessel_acted: bool | None
    own_course_deg_at_trigger: float
    own_speed_kn_at_trigger: float
    target_course_deg_at_trigger: float
    target_speed_kn_at_trigger: float
    target_length_m: float
    target_breadth_m: float
    target_draught_m: float
    target_dimensions_defaulted: bool


ENCOUNTER_COLUMNS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(EncounterSummary))

SERIES_COLUMNS: tuple[str, ...] = (
    "step",
    "timestamp",
    "own_lat_deg",
    "own_lon_deg",
    "own_north_m",
    "own_east_m",
    "own_cog_deg",
    "own_heading_deg",
    "own_course_deg",
    "own_sog_kn",
    "own_nav_status",
    "target_lat_deg",
    "target_lon_deg",
    "target_north_m",
    "target_east_m",
    "target_cog_deg",
    "target_heading_deg",
    "target_course_deg",
    "target_sog_kn",
    "target_nav_status",
    "range_m",
    "cpa_m",
    "tcpa_s",
    "beta_deg",
    "beta_prime_deg",
    "situation",
    "own_role_colregs",
    "target_role_colregs",
    "target_reports_restricted",
    "target_estimated_restricted",
    "restricted_assessed_utc",
    "automaton_state",
    "automaton_path",
    "rule9_applied",
    "own_role_final",
)


@dataclass(frozen=True)
class EncounterOutcome:
    """A triggered encounter: its verdict, time series and what its figure shows.

    ``own_track``/``target_track`` (``north_m``, ``east_m``) cover the whole encounter;
    ``*_at_tcpa_m`` are (north, east) predicted at constant velocity from the trigger to TCPA;
    ``assessment`` is the manoeuvrability estimate at the trigger.
    """

    summary: EncounterSummary
    series: pd.DataFrame
    own_track: pd.DataFrame
    target_track: pd.DataFrame
    own_at_tcpa_m: tuple[float, float]
    target_at_tcpa_m: tuple[float, float]
    assessment: ManoeuvrabilityAssessment


@dataclass(frozen=True)
class ReplayCounts:
    vessels: int
    segments: int
    candidate_pair_steps: int
    candidate_pairs: int
    encounters: int
    triggered: int


@dataclass(frozen=True)
class ReplayResult:
    """What ``colregs9 replay`` produced."""

    query_name: str
    out_dir: Path
    frame: LocalFrame
    params: ReplayRunParams
    encounters: tuple[EncounterOutcome, ...]
    counts: ReplayCounts
    manifest: dict[str, Any]
    files: tuple[Path, ...]

    @property
    def text(self) -> str:
        return format_summary(self)


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
    where = f"{query.source if query.source is not None else 'query'}"
    tables = query.tables
    replay = replay_params_from_table(dict(tables.get("replay", {})), f"{where} [replay]")
    colregs = colregs_params_from_table(dict(tables.get("colregs", {})), f"{where} [colregs]")
    manoeuvrability = ManoeuvrabilityParams.from_table(
        dict(tables.get("manoeuvrability", {})), f"{where} [manoeuvrability]"
    )
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


def run_frame(query: Query, positions: pd.DataFrame) -> LocalFrame:
    """The query region's frame, or one centred on the data's extent when there is none."""
    frame = query.frame()
    if frame is not None:
        return frame
    return LocalFrame.centred_on(
        float(positions["lat_deg"].min()),
        float(positions["lat_deg"].max()),
        float(positions["lon_deg"].min()),
        float(positions["lon_deg"].max()),
    )


def _ledger_with_tracks(ledger: RejectsLedger, tracks: Tracks) -> RejectsLedger:
    """The loader's ledger plus the reports that segmentation dropped."""
    result = copy.deepcopy(ledger)
    dropped = tracks.stats.same_time_dropped + tracks.stats.speed_jump_dropped
    result.rows_used -= dropped
    result.reject(RejectReason.DUPLICATE, tracks.stats.same_time_dropped)
    result.reject(RejectReason.SPEED_JUMP, tracks.stats.speed_jump_dropped)
    return result


def _text_or_none(value: Any) -> str | None:
    return None if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)


def _target_dimensions(
    vessels: pd.DataFrame, mmsi: int, defaults: TargetDimensions
) -> tuple[float, float, float, bool]:
    """(length, breadth, draught, defaulted) of a vessel, defaults for what she does not report."""
    values = []
    defaulted = False
    for name in ("length_m", "breadth_m", "draught_m"):
        value = vessels.at[mmsi, name] if name in vessels.columns else None
        if value is None or pd.isna(value) or float(value) <= 0.0:
            values.append(float(getattr(defaults, name)))
            defaulted = True
        else:
            values.append(float(value))
    return values[0], values[1], values[2], defaulted


def _nav_status(value: Any) -> int | None:
    return None if pd.isna(value) else int(value)


def _acted(course_deg: np.ndarray, speed_kn: np.ndarray, params: ReplayParams) -> bool:
    """Course changed by ≥ course_change_deg or speed by ≥ speed_change_frac vs the first step."""
    course_change = np.abs(signed_angle_deg(course_deg - course_deg[0]))
    if np.nanmax(course_change, initial=0.0) >= params.course_change_deg:
        return True
    if speed_kn[0] <= 0.0:
        return bool(np.nanmax(speed_kn, initial=0.0) > 0.0)
    speed_change = np.abs(speed_kn - speed_kn[0]) / speed_kn[0]
    return bool(np.nanmax(speed_change, initial=0.0) >= params.speed_change_frac)


@dataclass
class _Estimator:
    """The target's manoeuvrability estimate, made when needed and carried forward."""

    chart: Chart | None
    params: ManoeuvrabilityParams
    length_m: float
    breadth_m: float
    draught_m: float
    reassess_steps: int
    assessed_row: int = -1
    assessment: ManoeuvrabilityAssessment | None = None

    def at(
        self, target: dict[str, np.ndarray], row: int, needed: bool
    ) -> ManoeuvrabilityAssessment:
        """The estimate for ``row`` of the target's state arrays (made anew when due)."""
        stale = self.assessment is None or row - self.assessed_row >= self.reassess_steps
        if self.assessment is None or (needed and stale):
            self.assessment = assess_manoeuvrability(
                self.chart,
                float(target["north_m"][row]),
                float(target["east_m"][row]),
                float(target["course_deg"][row]),
                float(target["speed_mps"][row]),
                self.length_m,
                self.breadth_m,
                self.draught_m,
                self.params,
            )
            self.assessed_row = row
        return self.assessment


def pair_tracks(tracks: Tracks, mmsis: tuple[int, int]) -> Tracks:
    """The two vessels' tracks only: ``encounter_series`` then scans two tracks, not all.

    Relies on ``Tracks.samples`` being sorted by MMSI.
    """
    vessel = tracks.samples["mmsi"].to_numpy()
    parts = [
        tracks.samples.iloc[
            np.searchsorted(vessel, mmsi, "left") : np.searchsorted(vessel, mmsi, "right")
        ]
        for mmsi in mmsis
    ]
    return dataclasses.replace(tracks, samples=pd.concat(parts))


def evaluate_encounter(
    tracks: Tracks,
    encounter: Encounter,
    chart: Chart | None,
    params: ReplayRunParams,
) -> EncounterOutcome:
    """G_a and G_d at every step from the trigger until the pair passes or the encounter ends."""
    if encounter.trigger_step is None:
        raise ValueError(f"encounter {encounter.encounter_id} never triggered")
    full = encounter_series(
        pair_tracks(tracks, (encounter.own_mmsi, encounter.target_mmsi)), encounter
    )
    from_trigger = full[full["step"] >= encounter.trigger_step].reset_index(drop=True)
    passed = np.flatnonzero(from_trigger["tcpa_s"].to_numpy() < 0.0)
    series = from_trigger.iloc[: passed[0] if len(passed) else len(from_trigger)].copy()
    series = series.reset_index(drop=True)

    g_a = evaluate_colregs(
        Kinematics.from_frame(series, "own_"),
        Kinematics.from_frame(series, "target_"),
        params.colregs,
    )
    length_m, breadth_m, draught_m, defaulted = _target_dimensions(
        tracks.vessels, encounter.target_mmsi, params.replay.target_defaults
    )
    estimator = _Estimator(
        chart=chart,
        params=params.manoeuvrability,
        length_m=length_m,
        breadth_m=breadth_m,
        draught_m=draught_m,
        reassess_steps=max(1, round(params.replay.reassess_every_s / tracks.step_s)),
    )
    restricted_statuses = params.replay.restricted_nav_statuses
    verdicts: list[Rule9Assessment] = []
    runs: dict[tuple[Role, int | None, Restriction], Rule9Assessment] = {}
    estimates: list[Restriction] = []
    assessed_at: list[pd.Timestamp] = []
    trigger_assessment: ManoeuvrabilityAssessment | None = None
    nav_statuses = [_nav_status(v) for v in series["target_nav_status"].tolist()]
    timestamps = series["timestamp"].tolist()
    # The chart lives in the local frame, so the arcs start from the grid course.
    target_state = {
        name: series[f"target_{column}"].to_numpy(dtype=float)
        for name, column in (
            ("north_m", "north_m"),
            ("east_m", "east_m"),
            ("course_deg", "course_grid_deg"),
            ("speed_mps", "speed_mps"),
        )
    }
    for row, (own_role, nav_status) in enumerate(zip(g_a.own_role, nav_statuses, strict=True)):
        reaches_d3 = own_role is Role.STAND_ON and nav_status not in restricted_statuses
        assessment = estimator.at(target_state, row, needed=reaches_d3)
        if row == 0:
            trigger_assessment = assessment
        # G_d depends on these three observations only; most steps repeat the last ones.
        key = (own_role, nav_status, assessment.restriction)
        if key not in runs:
            runs[key] = assess_rule9(*key, restricted_statuses)
        verdicts.append(runs[key])
        estimates.append(assessment.restriction)
        assessed_at.append(timestamps[estimator.assessed_row])
    assert trigger_assessment is not None  # the trigger step is always in the series

    series["beta_deg"] = g_a.beta_deg
    series["beta_prime_deg"] = g_a.beta_prime_deg
    series["situation"] = [s.value for s in g_a.situation]
    series["own_role_colregs"] = [r.value for r in g_a.own_role]
    series["target_role_colregs"] = [r.value for r in g_a.target_role]
    series["target_reports_restricted"] = [s in restricted_statuses for s in nav_statuses]
    series["target_estimated_restricted"] = [e.value for e in estimates]
    series["restricted_assessed_utc"] = assessed_at
    series["automaton_state"] = [v.final_state.value for v in verdicts]
    series["automaton_path"] = [v.path_text for v in verdicts]
    series["rule9_applied"] = [v.rule9_applied for v in verdicts]
    series["own_role_final"] = [v.own_role_final.value for v in verdicts]

    trigger = series.iloc[0]
    verdict = verdicts[0]
    target_role_colregs = g_a.target_role[0]
    target_role_final = (
        target_role_colregs.inverted() if verdict.rule9_applied else target_role_colregs
    )
    give_way = [
        side
        for side, role in (("own", verdict.own_role_final), ("target", target_role_final))
        if role is Role.GIVE_WAY
    ]

    # The actual closest approach: over the whole encounter, and the first one after the trigger
    # ends the window in which the give-way vessel should have acted.
    min_row = int(full["range_m"].to_numpy().argmin())
    after = full[full["step"] >= encounter.trigger_step]
    cpa_row = int(after["range_m"].to_numpy().argmin())
    window = after.iloc[: cpa_row + 1]
    acted: bool | None = None
    if give_way:
        acted = all(
            _acted(
                window[f"{side}_course_deg"].to_numpy(dtype=float),
                window[f"{side}_sog_kn"].to_numpy(dtype=float),
                params.replay,
            )
            for side in give_way
        )

    tcpa_s = float(trigger["tcpa_s"])
    own_vn, own_ve = velocity_mps(trigger["own_speed_mps"], trigger["own_cog_grid_deg"])
    tgt_vn, tgt_ve = velocity_mps(trigger["target_speed_mps"], trigger["target_cog_grid_deg"])
    vessels = tracks.vessels
    summary = EncounterSummary(
        encounter_id=encounter.encounter_id,
        own_mmsi=encounter.own_mmsi,
        target_mmsi=encounter.target_mmsi,
        own_name=_text_or_none(vessels["name"].get(encounter.own_mmsi))
        if "name" in vessels.columns
        else None,
        target_name=_text_or_none(vessels["name"].get(encounter.target_mmsi))
        if "name" in vessels.columns
        else None,
        start_utc=encounter.start,
        trigger_utc=trigger["timestamp"],
        end_utc=encounter.end,
        situation=g_a.situation[0],
        own_role_colregs=g_a.own_role[0],
        target_role_colregs=target_role_colregs,
        target_nav_status=_nav_status(trigger["target_nav_status"]),
        target_reports_restricted=nav_statuses[0] in restricted_statuses,
        target_estimated_restricted=estimates[0],
        rule9_applied=verdict.rule9_applied,
        own_role_final=verdict.own_role_final,
        automaton_path=verdict.path_text,
        range_m_at_trigger=float(trigger["range_m"]),
        cpa_m=float(trigger["cpa_m"]),
        tcpa_s=tcpa_s,
        actual_min_separation_m=float(full.at[min_row, "range_m"]),
        actual_min_separation_utc=full.at[min_row, "timestamp"],
        give_way_vessel="+".join(give_way) if give_way else "none",
        give_way_vessel_acted=acted,
        own_course_deg_at_trigger=float(trigger["own_course_deg"]),
        own_speed_kn_at_trigger=float(trigger["own_sog_kn"]),
        target_course_deg_at_trigger=float(trigger["target_course_deg"]),
        target_speed_kn_at_trigger=float(trigger["target_sog_kn"]),
        target_length_m=length_m,
        target_breadth_m=breadth_m,
        target_draught_m=draught_m,
        target_dimensions_defaulted=defaulted,
    )
    return EncounterOutcome(
        summary=summary,
        series=series[list(SERIES_COLUMNS)],
        own_track=full[["own_north_m", "own_east_m"]].set_axis(["north_m", "east_m"], axis=1),
        target_track=full[["target_north_m", "target_east_m"]].set_axis(
            ["north_m", "east_m"], axis=1
        ),
        own_at_tcpa_m=(
            float(trigger["own_north_m"] + own_vn * tcpa_s),
            float(trigger["own_east_m"] + own_ve * tcpa_s),
        ),
        target_at_tcpa_m=(
            float(trigger["target_north_m"] + tgt_vn * tcpa_s),
            float(trigger["target_east_m"] + tgt_ve * tcpa_s),
        ),
        assessment=trigger_assessment,
    )


def _counts(tracks: Tracks, search: EncounterSearch) -> ReplayCounts:
    pairs = {frozenset((e.own_mmsi, e.target_mmsi)) for e in search.encounters}
    return ReplayCounts(
        vessels=len(tracks.vessels),
        segments=tracks.stats.segments,
        candidate_pair_steps=search.candidate_pair_steps,
        candidate_pairs=len(pairs),
        encounters=len(search.encounters),
        triggered=len(search.triggered),
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
    chart_paths: Sequence[Path], frame: LocalFrame, positions: pd.DataFrame
) -> Chart:
    """The charts in the run's frame; a chart that covers none of the AIS is an error.

    The boxes are compared first, so that a chart far away is never projected into the frame.
    """
    source = read_charts(chart_paths)
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
    data: AisData,
    ledger: RejectsLedger,
    chart_paths: Sequence[Path],
    frame: LocalFrame,
    params: ReplayRunParams,
    tracks: Tracks,
    counts: ReplayCounts,
    outcomes: tuple[EncounterOutcome, ...],
) -> dict[str, Any]:
    """The content of run.json."""
    return {
        **run_header("replay"),
        "query": query_manifest(query),
        "frame": {"lat0_deg": frame.lat0_deg, "lon0_deg": frame.lon0_deg},
        "parameters": jsonable(params),
        "inputs": inputs_manifest(data.inputs),
        "charts": [str(p) for p in chart_paths],
        "ledger": ledger.to_dict(),
        "ledger_balanced": ledger.balanced,
        "tracks": jsonable(tracks.stats),
        "counts": jsonable(counts),
        "verdicts": {
            "rule9_applied": sum(o.summary.rule9_applied for o in outcomes),
            "target_estimated_restricted": {
                value.value: sum(o.summary.target_estimated_restricted is value for o in outcomes)
                for value in Restriction
            },
        },
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
) -> ReplayResult:
    """Replay ``ais_paths`` and write the reports (see the module docstring).

    Errors: an own MMSI not in the data, fewer than two vessels (``NoDataError``, exit 3); a
    chart that covers none of the AIS (``ChartError``, exit 2); bad files or parameters. A run
    without triggered encounters is not an error: it writes a header-only encounters.csv.
    """
    query = load_query(query_path) if query_path is not None else everything_query()
    params = run_params(query, own_mmsi, overrides)
    data = load_ais(ais_paths, query=query, fmt=fmt, quiet=quiet)
    positions = data.positions
    vessels_in_data = positions["mmsi"].nunique()
    if vessels_in_data < 2:
        raise NoDataError(
            f"{', '.join(str(p) for p in ais_paths)}: the AIS selected by query "
            f"'{query.name}' holds {vessels_in_data} vessel(s); an encounter needs two. "
            "Widen the query or give more AIS"
        )
    frame = run_frame(query, positions)
    chart: Chart | None = None
    if chart_paths:
        chart = load_run_chart(chart_paths, frame, positions)

    tracks = build_tracks(positions, frame, params.replay, params.colregs.course_source)
    ledger = _ledger_with_tracks(data.ledger, tracks)
    search = find_encounters(tracks, params.replay, params.own_mmsi or None)
    triggered = search.triggered
    outcomes: list[EncounterOutcome] = []
    with progress_bar("encounters", len(triggered), progress_enabled(quiet)) as bar:
        for encounter in triggered:
            outcomes.append(evaluate_encounter(tracks, encounter, chart, params))
            bar.advance()
    counts = _counts(tracks, search)
    target = out_dir if out_dir is not None else default_out_dir(query.name)
    manifest = build_manifest(
        query, data, ledger, chart_paths, frame, params, tracks, counts, tuple(outcomes)
    )
    result = ReplayResult(
        query_name=query.name,
        out_dir=target,
        frame=frame,
        params=params,
        encounters=tuple(outcomes),
        counts=counts,
        manifest=manifest,
        files=(),
    )
    with progress_bar("reports", len(outcomes), progress_enabled(quiet)) as bar:
        files = write_replay_reports(result, chart, plots, bar)
    return dataclasses.replace(result, files=files)
