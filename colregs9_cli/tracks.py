"""Per-vessel tracks: segmentation and resampling to the replay time step (DESIGN §5 Replay).

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
4. **Missing SOG/COG.** A null SOG or COG is derived from the movement between the report's
   neighbours in its segment (previous to next report; one-sided at a segment's ends), turned
   from grid to true north at the report. A vessel that did not move gets SOG 0 and no COG
   (null). A one-report segment keeps nulls. A null heading becomes the (possibly derived) COG.
5. **Resampling.** Each segment is resampled on the absolute UTC grid ``t = k·step_s``
   (Unix epoch), at the grid times inside ``[first report, last report]``: nothing is
   extrapolated. North/east and SOG are linear in time; COG, heading and course are
   interpolated along the shorter arc (359° → 1° passes 0°, never 180°); the navigational
   status is the latest report's (held, not interpolated).

The course used for bearings (``course_deg``) is COG or heading (``CourseSource``); velocity
always comes from COG and SOG, the motion over ground.

``cog_deg``, ``heading_deg`` and ``course_deg`` are true, for reports. Each has a grid twin
(``cog_grid_deg`` …) in the frame's own north, ``true − γ`` with γ the meridian convergence at
the sample (``LocalFrame.grid_convergence_deg``): velocities in the frame and bearings compared
with frame positions must use the grid twins, or they turn by γ (≈ 2° at the edges of a frame
centred on all of Denmark, a CPA error of range·sin γ).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from .geo import LocalFrame, ecef_m, true_bearing_deg
from .replay_params import CourseSource, ReplayParams
from .units import MPS_PER_KNOT, signed_angle_deg, wrap_deg

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
STATIC_COLUMNS: tuple[str, ...] = (
    "name",
    "callsign",
    "imo",
    "ship_type",
    "mobile_type",
    "length_m",
    "breadth_m",
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
)
SAMPLE_COLUMNS: tuple[str, ...] = ("mmsi", "segment_id", "step", "t_s", "timestamp", *STATE_COLUMNS)


@dataclass(frozen=True)
class TrackStats:
    """What segmentation did, for the run manifest and the rejects ledger."""

    reports_in: int
    reports_used: int
    same_time_dropped: int
    speed_jump_dropped: int
    jump_splits: int
    gap_splits: int
    segments: int
    samples: int


@dataclass(frozen=True)
class Tracks:
    """Resampled tracks of all vessels.

    ``samples`` has one row per (``mmsi``, ``step``), sorted by ``mmsi`` then ``step``, with
    the columns ``SAMPLE_COLUMNS``: ``step`` is the integer k of the grid time
    ``t_s = k·step_s`` (seconds since the Unix epoch), ``timestamp`` the same instant in UTC,
    ``segment_id`` numbers segments over the whole run, ``nav_status`` is nullable ``Int64``.
    Angles are degrees in [0, 360) or NaN when unknown.

    ``vessels`` is indexed by ``mmsi`` (every vessel with samples) and holds the static
    columns present in the input, each the vessel's last non-null value (NaN/None if none).
    """

    samples: pd.DataFrame
    vessels: pd.DataFrame
    stats: TrackStats
    step_s: float
    frame: LocalFrame

    def step_to_timestamp(self, step: int) -> pd.Timestamp:
        return pd.Timestamp(step * self.step_s, unit="s", tz="UTC")


def build_tracks(
    positions: pd.DataFrame,
    frame: LocalFrame,
    params: ReplayParams,
    course_source: CourseSource = CourseSource.COG,
) -> Tracks:
    """Segment and resample ``positions`` (see the module docstring for the rules).

    ``positions`` must be cleaned: canonical columns, non-null positions and timestamps.
    A missing column or a null position is a programming error (``ValueError``).
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in positions.columns]
    if missing:
        raise ValueError(f"positions lack the canonical columns {missing}")
    if positions[["timestamp", "mmsi", "lat_deg", "lon_deg"]].isna().any().any():
        raise ValueError("positions must be cleaned: null timestamp, MMSI or position found")

    t_all = _epoch_seconds(positions["timestamp"])
    mmsi_all = positions["mmsi"].to_numpy(dtype=np.int64)
    order = np.lexsort((t_all, mmsi_all))
    mmsi = mmsi_all[order]
    t = t_all[order]
    reports_in = len(t)

    new_time = np.ones(len(t), dtype=bool)
    new_time[1:] = (mmsi[1:] != mmsi[:-1]) | (t[1:] != t[:-1])
    order, mmsi, t = order[new_time], mmsi[new_time], t[new_time]
    same_time_dropped = reports_in - len(t)

    report_lat = positions["lat_deg"].to_numpy(dtype=float)[order]
    report_lon = positions["lon_deg"].to_numpy(dtype=float)[order]
    # Distances between reports are measured on the Earth, not in the map frame, whose
    # scale grows away from its centre (a satellite feed's frame passes 2).
    where = ecef_m(report_lat, report_lon)
    keep, jump_split = _drop_jumps(mmsi, t, where, params)
    speed_jump_dropped = int((~keep).sum())
    order, mmsi, t, where = order[keep], mmsi[keep], t[keep], where[keep]
    report_lat, report_lon = report_lat[keep], report_lon[keep]
    jump_split = jump_split[keep]
    north, east = frame.to_local(report_lat, report_lon)

    first_of_vessel = np.ones(len(t), dtype=bool)
    first_of_vessel[1:] = mmsi[1:] != mmsi[:-1]
    gap = np.zeros(len(t), dtype=bool)
    gap[1:] = (t[1:] - t[:-1]) > params.max_gap_s
    gap &= ~first_of_vessel
    segment_start = first_of_vessel | gap | jump_split
    segment_of_report = np.cumsum(segment_start) - 1

    def column(name: str) -> NDArray[np.float64]:
        return pd.to_numeric(positions[name], errors="coerce").to_numpy(dtype=float)[order]

    sog_kn, cog_deg = _fill_motion(
        segment_of_report, t, report_lat, report_lon, column("sog_kn"), column("cog_deg")
    )
    heading_deg = column("heading_deg")
    heading_deg = np.where(np.isnan(heading_deg), cog_deg, heading_deg)
    course_deg = heading_deg if course_source is CourseSource.HEADING else cog_deg

    samples = _resample(
        segment_start,
        mmsi,
        t,
        {"north_m": north, "east_m": east, "sog_kn": sog_kn},
        {"cog_deg": cog_deg, "heading_deg": heading_deg, "course_deg": course_deg},
        column("nav_status"),
        params.step_s,
    )
    lat, lon = frame.to_geodetic(samples["north_m"], samples["east_m"])
    samples["lat_deg"] = lat
    samples["lon_deg"] = lon
    convergence_deg = frame.grid_convergence_deg(lat, lon)
    for name in ("cog", "heading", "course"):
        samples[f"{name}_grid_deg"] = wrap_deg(samples[f"{name}_deg"] - convergence_deg)
    samples["speed_mps"] = samples["sog_kn"] * MPS_PER_KNOT
    samples["timestamp"] = pd.to_datetime(samples["t_s"], unit="s", utc=True)
    samples = samples[list(SAMPLE_COLUMNS)]

    stats = TrackStats(
        reports_in=reports_in,
        reports_used=len(t),
        same_time_dropped=same_time_dropped,
        speed_jump_dropped=speed_jump_dropped,
        jump_splits=int(jump_split.sum()),
        gap_splits=int(gap.sum()),
        segments=int(segment_start.sum()),
        samples=len(samples),
    )
    return Tracks(
        samples=samples,
        vessels=_vessels(positions, samples["mmsi"].unique()),
        stats=stats,
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
    params: ReplayParams,
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
    last = np.r_[first[1:], len(t)] - 1
    # A tolerance keeps report times that are grid times (up to rounding) on the grid.
    k_first = np.ceil(t[first] / step_s - 1e-9).astype(np.int64)
    k_last = np.floor(t[last] / step_s + 1e-9).astype(np.int64)
    counts = np.maximum(k_last - k_first + 1, 0)
    sample_segment = np.repeat(np.arange(len(first)), counts)
    offsets = np.cumsum(counts) - counts
    step = k_first[sample_segment] + (np.arange(counts.sum()) - offsets[sample_segment])
    grid_t = step * step_s

    # Interval search on a key that is increasing over (segment, time).
    segment_of_report = np.cumsum(segment_start) - 1
    relative_t = t - t[first][segment_of_report]
    span = float(relative_t.max(initial=0.0)) + 2.0 * step_s + 1.0
    report_key = segment_of_report * span + relative_t
    sample_relative = grid_t - t[first][sample_segment]
    sample_key = sample_segment * span + sample_relative
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
    status_index = np.where(weight == 1.0, right, left)
    data["nav_status"] = pd.array(nav_status[status_index], dtype="Int64")
    return pd.DataFrame(data)


def _vessels(positions: pd.DataFrame, mmsis: NDArray[np.int64]) -> pd.DataFrame:
    present = [c for c in STATIC_COLUMNS if c in positions.columns]
    ordered = positions.sort_values("timestamp", kind="stable")
    statics = ordered.groupby("mmsi")[present].last() if present else None
    index = pd.Index(np.sort(mmsis), name="mmsi")
    if statics is None:
        return pd.DataFrame(index=index)
    return statics.reindex(index)
