"""The pass of a triggered pair audited: the least separation (antenna to antenna and hull to
hull) and what it rests on, and both vessels' conduct up to the closest approach
(docs/design.md §5, Replay). Vessel order (a, b), as in ``pair.py``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
import shapely

from .audit import INSUFFICIENT_CONDUCT, Conduct, ConductParams, conduct, observed_rows
from .hull import HullOffsets, least_hull_distance_geodetic_m, offsets_from_ais
from .passing import Passing, minimum_evidence
from .tracks import ANTENNA_OFFSET_COLUMNS
from .vessel_defaults import VesselDimensions

# The series' column prefixes of vessels a and b.
PREFIXES = ("own_", "target_")


@dataclass(frozen=True)
class PairAudit:
    """The pass and both vessels' conduct up to the closest approach (vessel order a, b)."""

    covers_cpa: bool
    min_separation_m: float | None
    cpa_utc: pd.Timestamp | None
    conducts: tuple[Conduct, Conduct]
    before_cpa_s: tuple[float | None, float | None]
    min_hull_separation_m: float | None = None
    # Either hull's antenna placed by assumption, not by her AIS A, B, C, D (None: no hull
    # distance).
    hull_antenna_position_assumed: bool | None = None
    # What the least separation rests on (passing.MinimumEvidence; None: no least separation).
    min_separation_report_gap_s: float | None = None
    min_separation_at_fixes_m: float | None = None
    min_separation_interpolated: bool | None = None
    # Either vessel's position at the least separation on the chart's land: a track drawn
    # across land between two reports (None: no chart, or no position in the chart's frame).
    min_separation_over_land: bool | None = None
    # Each vessel's reports over the passing (None: no row).
    report_gaps: tuple[ReportGaps | None, ReportGaps | None] = (None, None)

    def reports_sparse(self, vessel: int) -> bool | None:
        """Whether vessel ``vessel`` (0: a, 1: b) ran farther unseen between two of her
        reports than the pair's least separation: her interpolated track is then no
        observation at the scale the passing is judged on (None: no least separation)."""
        gaps = self.report_gaps[vessel]
        if gaps is None or self.min_separation_m is None:
            return None
        return gaps.run_unseen_m > self.min_separation_m


@dataclass(frozen=True)
class ReportGaps:
    """One vessel's reports over a passing: her longest time between two reports, and the
    farthest she ran between two reports (the gap times her speed there)."""

    largest_gap_s: float
    run_unseen_m: float


def report_gaps(window: pd.DataFrame, prefix: str) -> ReportGaps | None:
    """``ReportGaps`` over the rows of ``window`` (``tracks`` samples carry the gap between
    the two reports that bracket them, 0 at a report); None for no row."""
    if window.empty:
        return None
    gap_s = window[f"{prefix}report_gap_s"].to_numpy(dtype=float)
    run_m = gap_s * window[f"{prefix}speed_mps"].to_numpy(dtype=float)
    return ReportGaps(
        largest_gap_s=float(np.nanmax(gap_s, initial=0.0)),
        run_unseen_m=float(np.nanmax(run_m, initial=0.0)),
    )


def hull_offsets(dimensions: VesselDimensions, static: dict[str, Any]) -> HullOffsets:
    """A vessel's hull around her antenna: from her AIS A, B, C, D where her static row
    (``_static``: the four from one report, ``tracks.latest_statics``) has them, else from
    her reported length and breadth with the antenna amidships on the centre line, marked
    ``defaulted`` (``hull.offsets_from_ais``); unknown when neither gives both the length and
    the breadth (a table default is no hull)."""
    length_m = None if "length_m" in dimensions.defaulted else dimensions.length_m
    breadth_m = None if "breadth_m" in dimensions.defaulted else dimensions.breadth_m
    a, b, c, d = (static.get(name) for name in ANTENNA_OFFSET_COLUMNS)
    return offsets_from_ais(a, b, c, d, length_m, breadth_m)


def least_hull_separation_m(
    window: pd.DataFrame, offsets: tuple[HullOffsets, HullOffsets]
) -> float | None:
    """The least distance between the two hull outlines (``hull_offsets``) over ``window``
    (rows of the pair's series, headings true: COG where the heading was not reported);
    None where a hull is unknown."""
    if not all(o.known for o in offsets) or window.empty:
        return None
    a, b = PREFIXES
    distance = least_hull_distance_geodetic_m(
        window[f"{a}lat_deg"],
        window[f"{a}lon_deg"],
        window[f"{a}heading_deg"],
        offsets[0],
        window[f"{b}lat_deg"],
        window[f"{b}lon_deg"],
        window[f"{b}heading_deg"],
        offsets[1],
    )
    return float(np.nanmin(distance)) if np.isfinite(distance).any() else None


def over_land(land: Any, window: pd.DataFrame, row: int | None) -> bool | None:
    """Whether either vessel's position at ``row`` of ``window`` (the least separation) lies
    on ``land`` (the chart's land, in the frame of the window's ``north_m``/``east_m``):
    San Diego's SHELTER ISLAND, drawn straight across a spit between reports 120 s apart,
    "passed" SAILEBRATE at 55 m from dry land. None without land or a position."""
    if land is None or row is None:
        return None
    north = window[[f"{p}north_m" for p in PREFIXES]].iloc[row].to_numpy(dtype=float)
    east = window[[f"{p}east_m" for p in PREFIXES]].iloc[row].to_numpy(dtype=float)
    if not (np.isfinite(north).all() and np.isfinite(east).all()):
        return None
    return bool(shapely.contains_xy(land, east, north).any())


def audit_pair(
    window: pd.DataFrame,
    seen: Passing,
    hulls: tuple[HullOffsets, HullOffsets],
    lengths_m: tuple[float, float],
    params: ConductParams,
    step_s: float,
    bends_deg: tuple[np.ndarray, np.ndarray] | None = None,
) -> PairAudit:
    """The pass audited (module docstring). ``bends_deg``: for each vessel, how far the
    charted channel she proceeds along has turned since the trigger at each row up to the
    closest approach (``channel_audit.VesselInChannel.bend_deg``): her course is judged
    against it, so that following a bend is not a turn."""
    passed = window.iloc[: seen.end_row + 1]
    gaps = (report_gaps(passed, PREFIXES[0]), report_gaps(passed, PREFIXES[1]))
    if seen.cpa_row is None:
        return PairAudit(
            False,
            None,
            None,
            (INSUFFICIENT_CONDUCT, INSUFFICIENT_CONDUCT),
            (None, None),
            report_gaps=gaps,
        )
    audit = dataclasses.replace(
        _audit_conduct(window, seen, seen.cpa_row, hulls, params, step_s, bends_deg),
        report_gaps=gaps,
    )

    def both(name: str) -> np.ndarray:
        return window[[f"{prefix}{name}" for prefix in PREFIXES]].to_numpy(dtype=float)

    evidence = minimum_evidence(
        window["range_m"].to_numpy(dtype=float),
        both("report_gap_s"),
        both("nearest_report_s"),
        both("speed_mps"),
        lengths_m,
        seen,
        step_s,
    )
    if evidence is None:
        return audit
    return dataclasses.replace(
        audit,
        min_separation_report_gap_s=evidence.report_gap_s,
        min_separation_at_fixes_m=evidence.at_fixes_m,
        min_separation_interpolated=evidence.interpolated,
    )


def _audit_conduct(
    window: pd.DataFrame,
    seen: Passing,
    cpa_row: int,
    hulls: tuple[HullOffsets, HullOffsets],
    params: ConductParams,
    step_s: float,
    bends_deg: tuple[np.ndarray, np.ndarray] | None = None,
) -> PairAudit:
    cpa_utc = window["timestamp"].iloc[cpa_row]
    hull_m = least_hull_separation_m(window.iloc[: seen.end_row + 1], hulls)
    assumed = None if hull_m is None else any(h.defaulted for h in hulls)
    if not seen.covers_cpa:
        # The least range so far is observed, but the closest approach may lie past the data:
        # what the vessels did before it cannot be judged.
        return PairAudit(
            False,
            seen.min_separation_m,
            cpa_utc,
            (INSUFFICIENT_CONDUCT, INSUFFICIENT_CONDUCT),
            (None, None),
            hull_m,
            assumed,
        )
    conducts = tuple(
        conduct(
            _against_bend(window[f"{prefix}course_deg"].to_numpy(dtype=float), bends_deg, vessel),
            window[f"{prefix}sog_kn"].to_numpy(dtype=float),
            params,
            observed_rows(
                window[f"{prefix}report_gap_s"],
                window[f"{prefix}nearest_report_s"],
                step_s,
                params,
            ),
            last_row=cpa_row,
        )
        for vessel, prefix in enumerate(PREFIXES)
    )
    before = tuple(
        None if c.action_row is None else (cpa_row - c.action_row) * step_s for c in conducts
    )
    return PairAudit(
        covers_cpa=True,
        min_separation_m=seen.min_separation_m,
        cpa_utc=cpa_utc,
        conducts=(conducts[0], conducts[1]),
        before_cpa_s=(before[0], before[1]),
        min_hull_separation_m=hull_m,
        hull_antenna_position_assumed=assumed,
    )


def _against_bend(
    course_deg: np.ndarray, bends_deg: tuple[np.ndarray, np.ndarray] | None, vessel: int
) -> np.ndarray:
    """Her course less the channel's turn since the trigger, where she follows one (rows
    past the closest approach, read only to close its report gap, keep the turn there)."""
    if bends_deg is None:
        return course_deg
    bend = np.zeros(len(course_deg))
    known = np.nan_to_num(bends_deg[vessel][: len(course_deg)])
    bend[: len(known)] = known
    if len(known):
        bend[len(known) :] = known[-1]
    return course_deg - bend
