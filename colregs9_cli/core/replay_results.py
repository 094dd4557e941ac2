"""The results of ``colregs9 replay``: each triggered pair with its rows and, per reported seat,
its time series and what its figure shows; the run's counts and result. Below both
``jobs/replay.py`` (which fills them) and ``report/`` (which lays them out), so that every
import points down.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..geo import LocalFrame, velocity_mps
from .interactions import InteractionKind
from .manoeuvrability import ManoeuvrabilityAssessment
from .pair import PairParams
from .pair_model import PairEvaluation, Seat
from .rows import EncounterSummary, PairSummary, pair_row, seat_row, seat_series


@dataclass(frozen=True)
class EncounterOutcome:
    """One seat of a triggered pair: its row, time series and what its figure shows.

    ``own_track``/``target_track`` (``timestamp`` UTC, ``lat_deg``, ``lon_deg``, ``north_m``,
    ``east_m``) cover the encounter and the audit window after it; ``*_at_trigger_m`` are
    (north, east) at the trigger and ``*_at_tcpa_m`` predicted at constant velocity from the
    trigger to TCPA; ``assessment`` is the target's manoeuvrability at the trigger. These
    metres are in ``frame``: the run's frame, or, for a pair beyond its reach
    (``geo.FRAME_REACH_M``), a frame centred on the pair, where no chart and no arcs are drawn.
    """

    summary: EncounterSummary
    series: pd.DataFrame
    own_track: pd.DataFrame
    target_track: pd.DataFrame
    own_at_trigger_m: tuple[float, float]
    target_at_trigger_m: tuple[float, float]
    own_at_tcpa_m: tuple[float, float]
    target_at_tcpa_m: tuple[float, float]
    assessment: ManoeuvrabilityAssessment
    frame: LocalFrame
    in_run_frame: bool


@dataclass(frozen=True)
class PairOutcome:
    """A triggered pair: its pair-level row and one outcome per reported seat."""

    summary: PairSummary
    seats: tuple[EncounterOutcome, ...]


@dataclass(frozen=True)
class ReplayCounts:
    vessels: int
    segments: int
    candidate_pair_steps: int
    candidate_pairs: int
    encounters: int
    triggered: int
    triggered_pairs: int


@dataclass(frozen=True)
class ReplayResult:
    """What ``colregs9 replay`` produced."""

    query_name: str
    out_dir: Path
    frame: LocalFrame
    params: PairParams
    pairs: tuple[PairOutcome, ...]
    counts: ReplayCounts
    manifest: dict[str, Any]
    files: tuple[Path, ...]
    # Every vessel's track over the run, a row per vertex: ``mmsi``, ``piece`` (0, 1, … at
    # each track split), ``t_s`` (epoch seconds), ``lat_deg``, ``lon_deg``, ``reports``
    # (decided reports from it up to the next vertex), ``name``, ``ship_type``, ``length_m``
    # (``jobs/slabs.track_vertices``, thinned to one report in 10 s).
    vessel_tracks: pd.DataFrame
    text: str = ""  # the summary printed to stdout (report.replay_report.format_summary)

    @property
    def interaction_summary(self) -> str:
        """E.g. ``19 pairs: 17 encounters, 2 not-making-way``: the pairs by interaction."""
        kinds = [pair.summary.interaction for pair in self.pairs]
        parts = [
            f"{kinds.count(kind)} {'encounters' if kind is InteractionKind.ENCOUNTER else kind}"
            for kind in InteractionKind
            if kind in kinds
        ]
        return f"{len(kinds)} pairs" + (": " + ", ".join(parts) if parts else "")

    @property
    def encounters(self) -> tuple[EncounterOutcome, ...]:
        """Every reported seat, ordered by start, own MMSI and target MMSI."""
        return seats_in_order(self.pairs)

    @property
    def pairs_table(self) -> pd.DataFrame:
        """pairs.csv as a typed DataFrame (``summary_table``), a row per pair."""
        return summary_table([pair.summary for pair in self.pairs], PairSummary)

    @property
    def encounters_table(self) -> pd.DataFrame:
        """encounters.csv as a typed DataFrame (``summary_table``), a row per seat."""
        return summary_table([seat.summary for seat in self.encounters], EncounterSummary)

    @property
    def tracks_table(self) -> pd.DataFrame:
        """Both vessels' tracks of every seat (``tracks_table``), in the seats' order."""
        return tracks_table(self.encounters)


def _dtype(annotation: Any) -> Any:
    """The pandas dtype of a summary field: ``X | None`` as a nullable X, enums as text."""
    optional = isinstance(annotation, types.UnionType) and type(None) in typing.get_args(annotation)
    if isinstance(annotation, types.UnionType):
        annotation = next(a for a in typing.get_args(annotation) if a is not type(None))
    if annotation is bool:
        return "boolean" if optional else "bool"
    if annotation is int:
        return "Int64" if optional else "int64"
    if annotation is float:
        return "float64"
    if annotation is pd.Timestamp:
        return UTC_DTYPE
    if annotation is str or (isinstance(annotation, type) and issubclass(annotation, Enum)):
        return "str"
    return "object"  # a field of another type: as it is (tests/test_api.py asks for types)


# pandas' own resolution, that of the seats' series.
UTC_DTYPE = pd.DatetimeTZDtype("us", "UTC")


def summary_table(
    summaries: Sequence[PairSummary | EncounterSummary], row: type[PairSummary | EncounterSummary]
) -> pd.DataFrame:
    """``summaries`` (rows of type ``row``) as pairs.csv/encounters.csv's columns, typed by
    the fields: enums as their text, times as UTC timestamps, ``None`` as missing (nullable
    integers and booleans). The dtypes do not depend on the values: a run without pairs
    gives the same columns, empty."""
    records = [
        {
            name: value.value if isinstance(value, Enum) else value
            for name, value in dataclasses.asdict(summary).items()
        }
        for summary in summaries
    ]
    hints = typing.get_type_hints(row)
    table = pd.DataFrame.from_records(records, columns=list(hints))
    return table.astype({name: _dtype(hint) for name, hint in hints.items()})


TRACK_COLUMNS: tuple[str, ...] = (
    "encounter_id",
    "pair_id",
    "vessel",
    "mmsi",
    "timestamp",
    "lat_deg",
    "lon_deg",
    "north_m",
    "east_m",
)


def tracks_table(seats: Sequence[EncounterOutcome]) -> pd.DataFrame:
    """Own ship's then the target's track of each seat, one row per time step
    (``TRACK_COLUMNS``; ``vessel`` is ``own`` or ``target``). The metres are in each seat's
    ``frame``: the run's, or the pair's own beyond its reach (``in_run_frame``)."""
    parts = [
        track.assign(
            encounter_id=seat.summary.encounter_id,
            pair_id=seat.summary.pair_id,
            vessel=vessel,
            mmsi=getattr(seat.summary, f"{vessel}_mmsi"),
        )
        for seat in seats
        for vessel, track in (("own", seat.own_track), ("target", seat.target_track))
    ]
    columns = list(TRACK_COLUMNS)
    table = pd.concat(parts, ignore_index=True)[columns] if parts else pd.DataFrame(columns=columns)
    types_by_column: dict[str, Any] = dict.fromkeys(("encounter_id", "pair_id", "vessel"), "str")
    types_by_column |= {"mmsi": "int64", "timestamp": UTC_DTYPE}
    types_by_column |= dict.fromkeys(("lat_deg", "lon_deg", "north_m", "east_m"), "float64")
    return table.astype(types_by_column)


def seats_in_order(pairs: Sequence[PairOutcome]) -> tuple[EncounterOutcome, ...]:
    """The pairs' seats ordered by start, own MMSI and target MMSI: the order of the reports'
    rows. Slabs own the encounters that start in them, so the seats of consecutive slabs,
    each ordered, follow one another in this order."""
    seats = [seat for pair in pairs for seat in pair.seats]
    return tuple(
        sorted(
            seats, key=lambda o: (o.summary.start_utc, o.summary.own_mmsi, o.summary.target_mmsi)
        )
    )


def pair_outcome(pair: PairEvaluation, seats: Sequence[int], run_frame: LocalFrame) -> PairOutcome:
    """A triggered pair's rows, and one outcome per reported seat (``seats``: own MMSIs)."""
    summary = pair_row(pair, seats)
    outcomes = tuple(
        seat_outcome(pair.seen_from(own), summary, run_frame) for own in sorted(set(seats))
    )
    return PairOutcome(summary=summary, seats=outcomes)


def seat_outcome(seat: Seat, pair: PairSummary, run_frame: LocalFrame) -> EncounterOutcome:
    """The encounters.csv row, series and figure data of one seat of a pair."""
    full = seat.pair.full
    trigger = seat.pair.trigger
    tcpa_s = pair.tcpa_s
    metre_columns = [f"{p}{c}" for p in ("own_", "target_") for c in ("north_m", "east_m")]
    in_run_frame = bool(np.isfinite(full[metre_columns].to_numpy(dtype=float)).all())
    # A pair beyond the run frame's reach is drawn and mapped in a frame of its own.
    frame = (
        run_frame
        if in_run_frame
        else LocalFrame(float(trigger["own_lat_deg"]), float(trigger["own_lon_deg"]))
    )

    def at_trigger(prefix: str) -> tuple[float, float]:
        if in_run_frame:
            return float(trigger[f"{prefix}north_m"]), float(trigger[f"{prefix}east_m"])
        north, east = frame.to_local(trigger[f"{prefix}lat_deg"], trigger[f"{prefix}lon_deg"])
        return float(north), float(east)

    def at_tcpa(lat_lon_at_cpa: tuple[float, float], prefix: str) -> tuple[float, float]:
        if in_run_frame:
            v_north, v_east = velocity_mps(
                trigger[f"{prefix}speed_mps"], trigger[f"{prefix}cog_grid_deg"]
            )
            return (
                float(trigger[f"{prefix}north_m"] + v_north * tcpa_s),
                float(trigger[f"{prefix}east_m"] + v_east * tcpa_s),
            )
        north, east = frame.to_local(*lat_lon_at_cpa)
        return float(north), float(east)

    def track(prefix: str) -> pd.DataFrame:
        # The time and the position on the Earth beside the metres, for tables and maps.
        track = full[["timestamp", f"{prefix}lat_deg", f"{prefix}lon_deg"]].set_axis(
            ["timestamp", "lat_deg", "lon_deg"], axis=1
        )
        if in_run_frame:
            north, east = full[f"{prefix}north_m"], full[f"{prefix}east_m"]
        else:
            north, east = frame.to_local(track["lat_deg"], track["lon_deg"])
        return track.assign(north_m=north, east_m=east)

    own_prefix, target_prefix = seat.prefixes
    own, target = seat.own, seat.target
    return EncounterOutcome(
        summary=seat_row(seat, pair),
        series=seat_series(seat),
        own_track=track(own_prefix),
        target_track=track(target_prefix),
        own_at_trigger_m=at_trigger(own_prefix),
        target_at_trigger_m=at_trigger(target_prefix),
        own_at_tcpa_m=at_tcpa((own.lat_deg_at_cpa, own.lon_deg_at_cpa), own_prefix),
        target_at_tcpa_m=at_tcpa((target.lat_deg_at_cpa, target.lon_deg_at_cpa), target_prefix),
        assessment=seat.mine(seat.pair.steps.trigger_assessments)[1],
        frame=frame,
        in_run_frame=in_run_frame,
    )
