"""Per-vessel tracks: segmentation and resampling to the replay time step (docs/design.md §5).

Input: cleaned position reports in the canonical columns (``timestamp`` tz-aware UTC,
``mmsi``, ``lat_deg``, ``lon_deg``, ``sog_kn``, ``cog_deg``, ``heading_deg``, ``nav_status``,
optionally the static columns ``name``, ``callsign``, ``imo``, ``ship_type``, ``length_m``,
``breadth_m``, ``draught_m``) and the run's ``LocalFrame``. Output: a ``Tracks`` container.

The rules, in order, per MMSI with reports sorted by time:

1. **Same second.** A report with the same timestamp as an earlier report of the vessel is
   dropped (``same_time_dropped``; the caller counts it as a duplicate). Resampling needs
   strictly increasing times.
2. **Implausible jumps.** A report is a jump when the straight-line speed from the last kept
   report (within ``max_gap_s``) exceeds ``max_speed_kn``. If the next report confirms it (it
   is plausible from the jumping report and is itself a jump from the last kept report), the
   vessel really is there: the track is split at the jumping report (``jump_splits``, nothing
   lost). Otherwise the jumping report is dropped (``speed_jump_dropped``; the caller counts
   it as ``RejectReason.SPEED_JUMP``) and the next report is tested against the same anchor.
3. **Gaps.** A track is split where consecutive kept reports are more than ``max_gap_s`` apart
   (``gap_splits``).
3a. **Contradicted SOG.** A reported SOG is set to null, so that rule 4 derives it from the
   positions, where the vessel's own positions show she cannot have made it good
   (``sog_contradicted``; the caller counts it in the ledger's ``values_dropped``): between
   the report's neighbours in its segment (one-sided at a segment's end) she covered much
   less ground than the SOG claims (``ais_claims.SogCheckParams``: a yacht reporting
   102.2 kn from one fixed position). A SOG lower than the positions imply is kept: at low
   speed that is what GNSS scatter does to positions (a moored vessel's fixes 100 m apart).
4. **Missing SOG/COG.** A null SOG or COG is derived from the movement between the report's
   neighbours in its segment (previous to next report; one-sided at a segment's ends), turned
   from grid to true north at the report. A vessel that did not move gets SOG 0 and no COG
   (null). A one-report segment keeps nulls. A null heading becomes the (possibly derived) COG.
5. **Resampling.** Each segment is resampled on the absolute UTC grid ``t = k·step_s``
   (Unix epoch), at the grid times inside ``[first report, last report]``: nothing is
   extrapolated. North/east and SOG are linear in time; COG, heading and course are
   interpolated along the shorter arc (359° → 1° passes 0°, never 180°); the navigational
   status is the latest report's (held, not interpolated). Each sample carries
   ``report_gap_s``, the time between the two reports that bracket it (0 at a report's own
   time), ``nearest_report_s``, the time to the nearer of them, and ``gap_turn_deg``, how far
   her course turned between them (0 at a report): a position interpolated across a long gap
   is an estimate, not an observation (a river bend crossed by a 195 s gap), and so is a
   course interpolated across a turn.

The course used for bearings (``course_deg``) is COG or heading (``CourseSource``); velocity
always comes from COG and SOG, the motion over ground.

``cog_deg``, ``heading_deg`` and ``course_deg`` are true, for reports. Each has a grid twin
(``cog_grid_deg`` …) in the frame's own north, ``true − γ`` with γ the meridian convergence at
the sample (``LocalFrame.grid_convergence_deg``): velocities in the frame and bearings compared
with frame positions must use the grid twins, or they turn by γ (≈ 2° at the edges of a frame
centred on all of Denmark, a CPA error of range·sin γ).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..geo import LocalFrame, ecef_m, normal_to_lat_lon, surface_normal, true_bearing_deg
from ..units import MPS_PER_KNOT, signed_angle_deg, wrap_deg
from .ais_claims import Fixes, SogCheckParams, contradicted_sog


class CourseSource(StrEnum):
    """Which AIS field gives a vessel's course for bearings: COG, or heading (null → COG)."""

    COG = "cog"
    HEADING = "heading"


@dataclass(frozen=True)
class TrackParams:
    """What the tracks need (the ``[replay]`` keys of the same names).

    - ``step_s``: the replay time step Δt; tracks are resampled to multiples of it (UTC).
    - ``max_gap_s``: a track is split where two reports are more than this apart.
    - ``max_speed_kn``: a report whose implied speed from the previous kept report exceeds
      this is an implausible jump (rule 2).
    - ``min_sog_kn``: vessels slower than this are not under way: their samples are counted
      apart, and only vessels under way are kept for the pair search.
    - ``sog_check``: when a reported SOG is contradicted by the positions (rule 3a).
    """

    step_s: float = 1.0
    max_gap_s: float = 300.0
    max_speed_kn: float = 50.0
    min_sog_kn: float = 0.5
    sog_check: SogCheckParams = field(default_factory=SogCheckParams)


REQUIRED_COLUMNS: tuple[str, ...] = (
    "timestamp",
    "mmsi",
    "lat_deg",
    "lon_deg",
    "sog_kn",
    "cog_deg",
    "heading_deg",
    "nav_status",
)
# AIS A, B, C, D (the canonical schema's names): the antenna's distances to the bow, stern,
# port and starboard sides, taken together from one report (``latest_statics``).
ANTENNA_OFFSET_COLUMNS: tuple[str, ...] = ("to_bow_m", "to_stern_m", "to_port_m", "to_starboard_m")
STATIC_COLUMNS: tuple[str, ...] = (
    "name",
    "callsign",
    "imo",
    "ship_type",
    "mobile_type",
    "length_m",
    "breadth_m",
    *ANTENNA_OFFSET_COLUMNS,
    "draught_m",
)
# A vessel's resampled state at a step (true courses for reports, grid courses for geometry).
STATE_COLUMNS: tuple[str, ...] = (
    "north_m",
    "east_m",
    "lat_deg",
    "lon_deg",
    "cog_deg",
    "heading_deg",
    "course_deg",
    "cog_grid_deg",
    "heading_grid_deg",
    "course_grid_deg",
    "sog_kn",
    "speed_mps",
    "nav_status",
    "report_gap_s",
    "nearest_report_s",
    "gap_turn_deg",
)
SAMPLE_COLUMNS: tuple[str, ...] = ("mmsi", "segment_id", "step", "t_s", "timestamp", *STATE_COLUMNS)


@dataclass(frozen=True)
class TrackStats:
    """What segmentation did, for the run manifest and the rejects ledger.

    ``samples`` counts the resampled samples at which a vessel is under way
    (SOG ≥ ``min_sog_kn``): the samples the pair search works on. It does not depend on how
    the run is cut into slabs. ``sog_contradicted`` counts the reported SOGs set to null by
    rule 3a (their reports are used).
    """

    reports_in: int
    reports_used: int
    same_time_dropped: int
    speed_jump_dropped: int
    jump_splits: int
    gap_splits: int
    segments: int
    samples: int
    sog_contradicted: int

    def __add__(self, other: TrackStats) -> TrackStats:
        return TrackStats(
            *(getattr(self, f.name) + getattr(other, f.name) for f in dataclasses.fields(self))
        )


NO_TRACK_STATS = TrackStats(0, 0, 0, 0, 0, 0, 0, 0, 0)


@dataclass(frozen=True)
class Tracks:
    """Resampled tracks of all vessels.

    ``samples`` has one row per (``mmsi``, ``step``), sorted by ``mmsi`` then ``step``, with
    the columns ``SAMPLE_COLUMNS``: ``step`` is the integer k of the grid time
    ``t_s = k·step_s`` (seconds since the Unix epoch), ``timestamp`` the same instant in UTC,
    ``segment_id`` numbers the segments of these samples, ``nav_status`` is nullable
    ``Int64``. Angles are degrees in [0, 360) or NaN when unknown.

    ``vessels`` is indexed by ``mmsi`` and holds the static columns present in the input,
    each the vessel's last non-null value (NaN/None if none).
    """

    samples: pd.DataFrame
    vessels: pd.DataFrame
    stats: TrackStats
    step_s: float
    frame: LocalFrame

    def step_to_timestamp(self, step: int) -> pd.Timestamp:
        return pd.Timestamp(step * self.step_s, unit="s", tz="UTC")


# -- rules 1-3a: segmentation, in one go or slab by slab -------------------------------------
#
# A report's fate depends on the vessel's last kept report (the anchor) and, when it jumps,
# on the report after it. So segmentation can run through time slab by slab and decide every
# report exactly as in one go: each slab carries, per vessel, its anchor and at most one
# report still pending (the slab's last, a jump that the next report may confirm). Rule 3a
# judges a kept report's SOG by its neighbours: an anchor whose next kept report may still
# come within ``SogCheckParams.max_gap_s`` is held (carried, not yet given out) with its
# segment start and its previous kept report, and given out once its next is known.

REPORT_COLUMNS: tuple[str, ...] = (
    "mmsi",
    "t_s",
    "lat_deg",
    "lon_deg",
    "sog_kn",
    "cog_deg",
    "heading_deg",
    "nav_status",
)
KEPT_COLUMNS: tuple[str, ...] = (*REPORT_COLUMNS, "segment_start")
# A held anchor's previous kept report in its segment (NaN when none), for rule 3a.
PREVIOUS_COLUMNS: tuple[str, ...] = (
    "previous_t_s",
    "previous_lat_deg",
    "previous_lon_deg",
    "previous_cog_deg",
)
CARRY_COLUMNS: tuple[str, ...] = (
    *REPORT_COLUMNS,
    "pending",
    "held",
    "segment_start",
    *PREVIOUS_COLUMNS,
)


def report_table(positions: pd.DataFrame) -> pd.DataFrame:
    """Cleaned canonical positions as the reports segmentation reads (``REPORT_COLUMNS``:
    ``t_s`` seconds since the Unix epoch, numbers as float, NaN when unknown).

    A missing column or a null position is a programming error (``ValueError``).
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in positions.columns]
    if missing:
        raise ValueError(f"positions lack the canonical columns {missing}")
    if positions[["timestamp", "mmsi", "lat_deg", "lon_deg"]].isna().any().any():
        raise ValueError("positions must be cleaned: null timestamp, MMSI or position found")

    def number(name: str) -> NDArray[np.float64]:
        return pd.to_numeric(positions[name], errors="coerce").to_numpy(dtype=float)

    return pd.DataFrame(
        {
            "mmsi": positions["mmsi"].to_numpy(dtype=np.int64),
            "t_s": _epoch_seconds(positions["timestamp"]),
            **{name: number(name) for name in REPORT_COLUMNS[2:]},
        }
    )


def empty_carry() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "mmsi": np.zeros(0, dtype=np.int64),
            **{name: np.zeros(0) for name in REPORT_COLUMNS[1:]},
            **{name: np.zeros(0, dtype=bool) for name in ("pending", "held", "segment_start")},
            **{name: np.zeros(0) for name in PREVIOUS_COLUMNS},
        }
    )


@dataclass(frozen=True)
class Segmented:
    """One slab's segmentation: its decided kept reports (``KEPT_COLUMNS``, sorted by MMSI
    and time) with where segments start, the carry for the next slab, and the counts."""

    kept: pd.DataFrame
    carry: pd.DataFrame
    stats: TrackStats


def segment_reports(
    reports: pd.DataFrame,
    carry: pd.DataFrame,
    params: TrackParams,
    until_s: float | None = None,
) -> Segmented:
    """Rules 1-3a on ``reports`` (``REPORT_COLUMNS``), all earlier than ``until_s`` and later
    than every report of earlier slabs, continuing from ``carry``.

    ``until_s`` is where the next slab starts; ``None`` means the data ends here, and every
    pending report is decided (a jump nothing confirms is dropped) and every held one given
    out.
    """
    fresh_rows = reports.assign(
        pending=False,
        held=False,
        segment_start=False,
        **dict.fromkeys(PREVIOUS_COLUMNS, np.nan),
    )
    rows = pd.concat([carry, fresh_rows], ignore_index=True)
    carried = np.r_[np.ones(len(carry), dtype=bool), np.zeros(len(reports), dtype=bool)]
    mmsi_all = rows["mmsi"].to_numpy(dtype=np.int64)
    t_all = rows["t_s"].to_numpy(dtype=float)
    # Of two reports at the same time the first in this order is kept: by their values,
    # not by the order of the input rows, so that the files' order cannot change a track.
    values = [rows[name].to_numpy(dtype=float) for name in reversed(REPORT_COLUMNS[2:])]
    order = np.lexsort((*values, ~carried, t_all, mmsi_all))
    mmsi, t = mmsi_all[order], t_all[order]

    new_time = np.ones(len(t), dtype=bool)
    new_time[1:] = (mmsi[1:] != mmsi[:-1]) | (t[1:] != t[:-1])
    order, mmsi, t = order[new_time], mmsi[new_time], t[new_time]
    same_time_dropped = int((~new_time).sum())

    lat = rows["lat_deg"].to_numpy(dtype=float)[order]
    lon = rows["lon_deg"].to_numpy(dtype=float)[order]
    # Distances between reports are measured on the Earth, not in the map frame, whose
    # scale grows away from its centre (a satellite feed's frame passes 2).
    keep, jump_split = _drop_jumps(mmsi, t, ecef_m(lat, lon), params)
    last_of_vessel = np.r_[mmsi[1:] != mmsi[:-1], True]
    # A jump at the end of the slab is decided by the next report, unless none can come in
    # time to confirm it.
    undecided = last_of_vessel & ~keep
    if until_s is None:
        undecided[:] = False
    else:
        undecided &= t >= until_s - params.max_gap_s
    anchor = carried[order] & ~rows["pending"].to_numpy(dtype=bool)[order]
    held = rows["held"].to_numpy(dtype=bool)[order]

    kept = keep.copy()
    first_of_vessel = np.ones(len(t), dtype=bool)
    kept_index = np.flatnonzero(kept)
    kept_mmsi, kept_t = mmsi[kept_index], t[kept_index]
    first = np.r_[True, kept_mmsi[1:] != kept_mmsi[:-1]]
    gap = np.r_[False, (kept_t[1:] - kept_t[:-1]) > params.max_gap_s] & ~first
    first_of_vessel[kept_index] = first
    gap_at = np.zeros(len(t), dtype=bool)
    gap_at[kept_index] = gap
    # A held anchor starts a segment as it did when it was kept.
    carried_start = rows["segment_start"].to_numpy(dtype=bool)[order]
    segment_start = np.where(held, carried_start, first_of_vessel | gap_at | jump_split)
    newly_kept = kept & ~anchor

    last = np.r_[kept_mmsi[1:] != kept_mmsi[:-1], True]
    last_kept = kept_index[last]
    # Rule 3a: a vessel's last kept report, not given out yet, waits for its next while one
    # may still come.
    neighbour_gap_s = min(params.sog_check.max_gap_s, params.max_gap_s)
    awaiting = np.zeros(len(t), dtype=bool)
    if until_s is not None:
        awaiting[last_kept] = t[last_kept] >= until_s - neighbour_gap_s
    awaiting &= newly_kept | held
    emitted = (newly_kept | held) & ~awaiting
    own, previous, following = _neighbours(
        rows, order, kept_index, first, last, segment_start, lat, lon
    )
    contradicted = np.zeros(len(t), dtype=bool)
    contradicted[kept_index] = contradicted_sog(
        rows["sog_kn"].to_numpy(dtype=float)[order[kept_index]],
        own,
        previous,
        following,
        params.sog_check,
    )

    next_carry = np.zeros(len(t), dtype=bool)
    next_carry[last_kept] = True
    next_carry |= undecided
    out = rows.iloc[order[emitted]][list(REPORT_COLUMNS)].reset_index(drop=True)
    out["sog_kn"] = np.where(contradicted[emitted], np.nan, out["sog_kn"].to_numpy(dtype=float))
    out["segment_start"] = segment_start[emitted]
    carry_rows = rows.iloc[order[next_carry]][list(REPORT_COLUMNS)].reset_index(drop=True)
    carry_rows["pending"] = undecided[next_carry]
    carry_rows["held"] = awaiting[next_carry]
    carry_rows["segment_start"] = segment_start[next_carry]
    previous_table = np.full((len(t), len(PREVIOUS_COLUMNS)), np.nan)
    previous_table[kept_index] = previous.table()
    for column, name in enumerate(PREVIOUS_COLUMNS):
        carry_rows[name] = previous_table[next_carry, column]
    stats = TrackStats(
        reports_in=len(reports),
        reports_used=int(newly_kept.sum()),
        same_time_dropped=same_time_dropped,
        speed_jump_dropped=int((~keep & ~undecided).sum()),
        jump_splits=int((jump_split & newly_kept).sum()),
        gap_splits=int((gap_at & newly_kept).sum()),
        segments=int((segment_start & newly_kept).sum()),
        samples=0,
        sog_contradicted=int((contradicted & emitted).sum()),
    )
    return Segmented(kept=out, carry=carry_rows, stats=stats)


def _neighbours(
    rows: pd.DataFrame,
    order: NDArray[np.int64],
    kept_index: NDArray[np.int64],
    first: NDArray[np.bool_],
    last: NDArray[np.bool_],
    segment_start: NDArray[np.bool_],
    lat_deg: NDArray[np.float64],
    lon_deg: NDArray[np.float64],
) -> tuple[Fixes, Fixes, Fixes]:
    """The kept reports (``kept_index`` into the sorted ``order`` of ``rows``; ``first`` and
    ``last`` of their vessel here) and their neighbours, the kept reports before and after
    in the same segment (NaN: none, or not known yet); a carried anchor brings its previous
    one with it."""
    chosen = order[kept_index]

    def column(name: str) -> NDArray[np.float64]:
        return rows[name].to_numpy(dtype=float)[chosen]

    own = Fixes(column("t_s"), lat_deg[kept_index], lon_deg[kept_index], column("cog_deg"))
    starts = segment_start[kept_index]
    index = np.arange(len(kept_index))
    carried = Fixes(*(column(name) for name in PREVIOUS_COLUMNS))
    previous = carried.where(first, own.take(np.maximum(index - 1, 0), ~first & ~starts))
    following = own.take(np.minimum(index + 1, len(index) - 1), ~last & ~np.r_[starts[1:], False])
    return own, previous, following


# -- rules 4-5: motion and resampling of decided reports --------------------------------------


def resample_reports(
    kept: pd.DataFrame,
    frame: LocalFrame,
    params: TrackParams,
    course_source: CourseSource = CourseSource.COG,
    steps: tuple[int, int] | None = None,
    under_way_only: bool = False,
) -> pd.DataFrame:
    """Rules 4 and 5 on decided kept reports (``KEPT_COLUMNS``, sorted by MMSI and time):
    the samples (``SAMPLE_COLUMNS``) at the grid steps ``steps`` (inclusive; default all).

    A vessel's first report here starts a segment. Samples at steps whose neighbouring
    reports (and theirs, for rule 4) are all present are exact; the caller gives enough
    reports around ``steps`` (``context_s``). With ``under_way_only``, only vessels with a
    report under way (SOG ≥ ``min_sog_kn``) within ``max_gap_s`` of ``steps`` are resampled:
    the others cannot be in a pair there.
    """
    mmsi = kept["mmsi"].to_numpy(dtype=np.int64)
    t = kept["t_s"].to_numpy(dtype=float)
    segment_start = kept["segment_start"].to_numpy(dtype=bool) | np.r_[True, mmsi[1:] != mmsi[:-1]]
    segment_of_report = np.cumsum(segment_start) - 1
    lat = kept["lat_deg"].to_numpy(dtype=float)
    lon = kept["lon_deg"].to_numpy(dtype=float)
    sog_kn, cog_deg = _fill_motion(
        segment_of_report,
        t,
        lat,
        lon,
        kept["sog_kn"].to_numpy(dtype=float),
        kept["cog_deg"].to_numpy(dtype=float),
    )
    if under_way_only:
        near = np.ones(len(t), dtype=bool)
        if steps is not None:
            near = (t >= steps[0] * params.step_s - params.max_gap_s) & (
                t <= steps[1] * params.step_s + params.max_gap_s
            )
        moving = np.unique(mmsi[near & (sog_kn >= params.min_sog_kn)])
        chosen = np.isin(mmsi, moving)
        mmsi, t, lat, lon = mmsi[chosen], t[chosen], lat[chosen], lon[chosen]
        sog_kn, cog_deg = sog_kn[chosen], cog_deg[chosen]
        segment_start = segment_start[chosen] | np.r_[True, mmsi[1:] != mmsi[:-1]]
        kept = kept[chosen]
    heading_deg = kept["heading_deg"].to_numpy(dtype=float)
    heading_deg = np.where(np.isnan(heading_deg), cog_deg, heading_deg)
    course_deg = heading_deg if course_source is CourseSource.HEADING else cog_deg
    # Positions are interpolated on the Earth (surface normals), not in the map frame, which
    # is undefined far from its centre; the frame's coordinates are then only derived.
    normal = surface_normal(lat, lon)
    samples = _resample(
        segment_start,
        mmsi,
        t,
        {
            "normal_x": normal[:, 0],
            "normal_y": normal[:, 1],
            "normal_z": normal[:, 2],
            "sog_kn": sog_kn,
        },
        {"cog_deg": cog_deg, "heading_deg": heading_deg, "course_deg": course_deg},
        kept["nav_status"].to_numpy(dtype=float),
        params.step_s,
    )
    if steps is not None:
        samples = samples[samples["step"].between(*steps)].reset_index(drop=True)
    sample_lat, sample_lon = normal_to_lat_lon(
        samples["normal_x"], samples["normal_y"], samples["normal_z"]
    )
    samples["lat_deg"] = sample_lat
    samples["lon_deg"] = sample_lon
    north, east = frame.to_local(sample_lat, sample_lon)
    # Beyond the frame's reach its scale bends (and PROJ may answer inf): such a sample has
    # no frame position, while its geometry between vessels stays exact.
    placed = frame.within_reach(sample_lat, sample_lon) & np.isfinite(north) & np.isfinite(east)
    samples["north_m"] = np.where(placed, north, np.nan)
    samples["east_m"] = np.where(placed, east, np.nan)
    convergence_deg = frame.grid_convergence_deg(sample_lat, sample_lon)
    for name in ("cog", "heading", "course"):
        samples[f"{name}_grid_deg"] = wrap_deg(samples[f"{name}_deg"] - convergence_deg)
    samples["speed_mps"] = samples["sog_kn"] * MPS_PER_KNOT
    samples["timestamp"] = pd.to_datetime(samples["t_s"], unit="s", utc=True)
    return samples[list(SAMPLE_COLUMNS)]


def context_s(params: TrackParams) -> float:
    """How far around a window of steps the reports must reach for its samples to be exact:
    the reports bracketing a sample are within ``max_gap_s`` of it, and rule 4 looks at
    their neighbours, within ``max_gap_s`` again."""
    return 2.0 * params.max_gap_s + 2.0 * params.step_s


def build_tracks(
    positions: pd.DataFrame,
    frame: LocalFrame,
    params: TrackParams,
    course_source: CourseSource = CourseSource.COG,
) -> Tracks:
    """Segment and resample ``positions`` in one go (see the module docstring for the rules).

    ``positions`` must be cleaned: canonical columns, non-null positions and timestamps.
    A missing column or a null position is a programming error (``ValueError``).
    """
    segmented = segment_reports(report_table(positions), empty_carry(), params)
    samples = resample_reports(segmented.kept, frame, params, course_source)
    under_way = int((samples["sog_kn"].to_numpy() >= params.min_sog_kn).sum())
    return Tracks(
        samples=samples,
        vessels=vessel_statics(positions, samples["mmsi"].unique()),
        stats=dataclasses.replace(segmented.stats, samples=under_way),
        step_s=params.step_s,
        frame=frame,
    )


def _epoch_seconds(timestamps: pd.Series) -> NDArray[np.float64]:
    stamps = pd.to_datetime(timestamps, utc=True).dt.as_unit("ns")
    return stamps.astype("int64").to_numpy() / 1e9


def _drop_jumps(
    mmsi: NDArray[np.int64],
    t: NDArray[np.float64],
    where: NDArray[np.float64],
    params: TrackParams,
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """(keep, split) masks for rule 2. Only vessels with a consecutive jump are walked.

    ``where`` holds the reports' Earth-centred positions (``geo.ecef_m``); distances are the
    chords between them, the geodesic distance to 1 mm in 10 km.
    """
    keep = np.ones(len(t), dtype=bool)
    split = np.zeros(len(t), dtype=bool)
    max_speed_mps = params.max_speed_kn * MPS_PER_KNOT
    same = mmsi[1:] == mmsi[:-1]
    dt = t[1:] - t[:-1]
    implied = np.linalg.norm(np.diff(where, axis=0), axis=-1) / np.where(dt > 0, dt, np.inf)
    jumps = same & (dt <= params.max_gap_s) & (implied > max_speed_mps)
    if not jumps.any():
        return keep, split
    starts = np.flatnonzero(np.r_[True, ~same])
    ends = np.r_[starts[1:], len(t)]
    vessel_has_jump = np.add.reduceat(np.r_[False, jumps].astype(int), starts) > 0
    for start, end in zip(starts[vessel_has_jump], ends[vessel_has_jump], strict=True):
        _walk_jumps(
            t[start:end],
            where[start:end],
            params.max_gap_s,
            max_speed_mps,
            keep[start:end],
            split[start:end],
        )
    return keep, split


def _walk_jumps(
    t: NDArray[np.float64],
    where: NDArray[np.float64],
    max_gap_s: float,
    max_speed_mps: float,
    keep: NDArray[np.bool_],
    split: NDArray[np.bool_],
) -> None:
    """Rule 2 for one vessel, writing into the ``keep`` and ``split`` views."""

    def plausible(i: int, j: int) -> bool:
        dt = t[j] - t[i]
        return dt > max_gap_s or float(np.linalg.norm(where[j] - where[i])) <= (max_speed_mps * dt)

    anchor = 0
    for i in range(1, len(t)):
        if plausible(anchor, i):
            anchor = i
            continue
        following = i + 1
        confirmed = (
            following < len(t)
            and t[following] - t[i] <= max_gap_s
            and plausible(i, following)
            and not plausible(anchor, following)
        )
        if confirmed:
            split[i] = True
            anchor = i
        else:
            keep[i] = False


def _fill_motion(
    segment: NDArray[np.int64],
    t: NDArray[np.float64],
    lat_deg: NDArray[np.float64],
    lon_deg: NDArray[np.float64],
    sog_kn: NDArray[np.float64],
    cog_deg: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rule 4: null SOG/COG from the movement between the report's neighbours.

    The movement is measured on the Earth: its length as the chord between the two
    positions, its direction as the true bearing at the earlier one.
    """
    index = np.arange(len(t))
    previous = np.where(np.r_[False, segment[1:] == segment[:-1]], index - 1, index)
    following = np.where(np.r_[segment[:-1] == segment[1:], False], index + 1, index)
    where = ecef_m(lat_deg, lon_deg)
    distance = np.linalg.norm(where[following] - where[previous], axis=-1)
    dt = t[following] - t[previous]
    with np.errstate(invalid="ignore", divide="ignore"):
        derived_sog = np.where(dt > 0, distance / dt / MPS_PER_KNOT, np.nan)
    bearing = true_bearing_deg(
        lat_deg[previous], lon_deg[previous], lat_deg[following], lon_deg[following]
    )
    derived_cog = np.where(distance > 0, bearing, np.nan)
    return (
        np.where(np.isnan(sog_kn), derived_sog, sog_kn),
        np.where(np.isnan(cog_deg), derived_cog, cog_deg),
    )


def _resample(
    segment_start: NDArray[np.bool_],
    mmsi: NDArray[np.int64],
    t: NDArray[np.float64],
    linear: dict[str, NDArray[np.float64]],
    circular: dict[str, NDArray[np.float64]],
    nav_status: NDArray[np.float64],
    step_s: float,
) -> pd.DataFrame:
    """Rule 5, vectorised over all segments at once."""
    first = np.flatnonzero(segment_start)
    last = np.append(first[1:], len(t))[: len(first)] - 1
    # A tolerance keeps report times that are grid times (up to rounding) on the grid.
    k_first = np.ceil(t[first] / step_s - 1e-9).astype(np.int64)
    k_last = np.floor(t[last] / step_s + 1e-9).astype(np.int64)
    counts = np.maximum(k_last - k_first + 1, 0)
    sample_segment = np.repeat(np.arange(len(first)), counts)
    offsets = np.cumsum(counts) - counts
    step = k_first[sample_segment] + (np.arange(counts.sum()) - offsets[sample_segment])
    grid_t = step * step_s

    # Interval search on an integer key, increasing over (segment, time) in milliseconds:
    # exact, so that a sample finds the same reports whatever else is resampled with it.
    segment_of_report = np.cumsum(segment_start) - 1
    report_ms = np.rint(t * 1000.0).astype(np.int64)
    relative_ms = report_ms - report_ms[first][segment_of_report]
    span_ms = int(relative_ms.max(initial=0)) + 1
    report_key = segment_of_report * span_ms + relative_ms
    grid_ms = np.rint(grid_t * 1000.0).astype(np.int64)
    sample_relative_ms = grid_ms - report_ms[first][sample_segment]
    sample_key = sample_segment * span_ms + np.clip(sample_relative_ms, 0, span_ms - 1)
    left = np.searchsorted(report_key, sample_key, side="right") - 1
    left = np.clip(left, first[sample_segment], last[sample_segment])
    right = np.minimum(left + 1, last[sample_segment])
    dt = t[right] - t[left]
    with np.errstate(invalid="ignore", divide="ignore"):
        weight = np.clip(np.where(dt > 0, (grid_t - t[left]) / dt, 0.0), 0.0, 1.0)

    def blend(start: NDArray[np.float64], change: NDArray[np.float64]) -> NDArray[np.float64]:
        # At a report time (weight 0) the report's own value holds even if the next is unknown.
        return np.where(weight == 0.0, start, start + weight * change)

    data: dict[str, object] = {
        "mmsi": mmsi[first][sample_segment],
        "segment_id": sample_segment.astype(np.int64),
        "step": step,
        "t_s": grid_t,
    }
    for name, values in linear.items():
        data[name] = blend(values[left], values[right] - values[left])
    for name, values in circular.items():
        data[name] = wrap_deg(blend(values[left], signed_angle_deg(values[right] - values[left])))
    # At a report's own time (weight 0) the sample is that report, whatever the next one.
    data["report_gap_s"] = np.where(weight > 0.0, dt, 0.0)
    data["nearest_report_s"] = np.where(
        weight > 0.0, np.minimum(grid_t - t[left], t[right] - grid_t), 0.0
    )
    course = circular["course_deg"]
    data["gap_turn_deg"] = np.where(
        weight > 0.0, np.abs(signed_angle_deg(course[right] - course[left])), 0.0
    )
    status_index = np.where(weight == 1.0, right, left)
    data["nav_status"] = pd.array(nav_status[status_index], dtype="Int64")
    return pd.DataFrame(data)


def latest_statics(positions: pd.DataFrame, earlier: pd.DataFrame | None = None) -> pd.DataFrame:
    """Each vessel's last non-null value of each static column in ``positions``, else its
    value in ``earlier`` (the same from earlier positions), indexed by MMSI.

    The antenna offsets (``ANTENNA_OFFSET_COLUMNS``) are taken together, all four from her
    last report with any of them (its nulls kept), else all four from ``earlier``: A from
    one report and B from another could draw a hull no report described."""
    present = [c for c in STATIC_COLUMNS if c in positions.columns]
    offsets = [c for c in ANTENNA_OFFSET_COLUMNS if c in present]
    ordered = positions.sort_values("timestamp", kind="stable")
    latest = ordered.groupby("mmsi")[[c for c in present if c not in offsets]].last()
    if offsets:
        reported = ordered[ordered[offsets].notna().any(axis=1)]
        last = reported.drop_duplicates("mmsi", keep="last").set_index("mmsi")[offsets]
        latest = latest.join(last)[present]
    if earlier is None or earlier.empty:
        return latest
    if latest.empty:
        return earlier
    combined = latest.combine_first(earlier)[present]
    together = [c for c in offsets if c in earlier.columns]
    if together:
        # combine_first fills column by column: where the latest positions report any
        # offset, all four are theirs.
        own = latest[together].notna().any(axis=1)
        rows = own.index[own.to_numpy()]
        combined.loc[rows, together] = latest.loc[rows, together]
    return combined


def vessel_statics(
    positions: pd.DataFrame | None, mmsis: ArrayLike, statics: pd.DataFrame | None = None
) -> pd.DataFrame:
    """The static table of ``Tracks.vessels`` for ``mmsis``: from ``statics``
    (``latest_statics``) when given, else from ``positions``."""
    if statics is None:
        statics = latest_statics(positions) if positions is not None else pd.DataFrame()
    index = pd.Index(np.sort(np.asarray(mmsis, dtype=np.int64)), name="mmsi")
    return statics.reindex(index)
