"""``colregs9 simulate``: a scenario file → synthetic AIS in the DMA 26-column CSV layout.

Each vessel runs along its route at the leg speeds. Her state is evaluated at every
integration step ``step_s`` in a local metric frame centred on the scenario's waypoints
(exact along straight legs: the time at each waypoint is the sum of leg length over leg
speed, and a step that passes a waypoint carries on along the next leg). A report is
emitted every ``ais_interval_s`` from the start, for ``0 <= t < duration_s``.

- COG is the course of the current leg (true degrees, one decimal), Heading is COG rounded,
  SOG the leg speed, ROT 0 (legs are straight; turns at waypoints are instantaneous).
- Until ``depart_s`` a vessel lies at her first waypoint, reporting it with SOG 0 and the
  course of her first leg; her route starts then. At the end of her route she stops there:
  she keeps reporting her last position with SOG 0 and the course of her last leg, so every
  vessel has the same number of reports.
- Static data comes with every report, as in the DMA files: A = B = length/2,
  C = D = breadth/2, Width, Length, Draught, Ship type, Name, Callsign, IMO ("Unknown" if
  none), "Class A", position fixing device "GPS".
"""

from __future__ import annotations

import datetime as dt
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..ais.layouts import DMA26
from ..geo import LocalFrame
from ..outputs import check_out_file
from ..progress import progress_bar, progress_enabled
from ..units import knots_to_mps, wrap_deg
from .scenario import (
    Scenario,
    VesselSpec,
    check_scenario_chart,
    load_scenario,
    scenario_frame,
)

# The layout simulate writes, through its writer: the columns, time format and status texts.
_DMA_CSV = DMA26.csv_writer()


@dataclass(frozen=True)
class VesselTrack:
    """One vessel's simulated reports, in the scenario's local frame."""

    vessel: VesselSpec
    time_s: np.ndarray
    north_m: np.ndarray
    east_m: np.ndarray
    lat_deg: np.ndarray
    lon_deg: np.ndarray
    sog_kn: np.ndarray
    cog_deg: np.ndarray


@dataclass(frozen=True)
class SimulationResult:
    scenario: Scenario
    out_path: Path
    tracks: tuple[VesselTrack, ...]
    rows: int

    @property
    def text(self) -> str:
        lines = [
            f"Scenario {self.scenario.name}: {len(self.tracks)} vessels, "
            f"{self.scenario.duration_s:g} s, {self.rows} AIS reports"
        ]
        for track in self.tracks:
            vessel = track.vessel
            lines.append(
                f"  {vessel.role.value:6} {vessel.mmsi} {vessel.name}: {len(track.time_s)} reports"
            )
        return "\n".join(lines) + "\n"


def report_times_s(scenario: Scenario) -> np.ndarray:
    """Report times: every ``ais_interval_s`` from 0, below ``duration_s``."""
    steps_per_report = round(scenario.ais_interval_s / scenario.step_s)
    steps = np.arange(0, math.ceil(scenario.duration_s / scenario.step_s - 1e-9))
    return steps[steps % steps_per_report == 0] * scenario.step_s


def simulate_vessel(vessel: VesselSpec, frame: LocalFrame, times_s: np.ndarray) -> VesselTrack:
    """Positions, SOG and COG along the route at ``times_s`` (seconds from the start)."""
    lats, lons = zip(*vessel.route, strict=True)
    north_m, east_m = frame.to_local(np.array(lats), np.array(lons))
    d_north = np.diff(north_m)
    d_east = np.diff(east_m)
    leg_m = np.hypot(d_north, d_east)
    leg_speed_mps = knots_to_mps(vessel.speed_kn)
    leg_course_deg = wrap_deg(np.degrees(np.arctan2(d_east, d_north)))
    waypoint_time_s = vessel.depart_s + np.concatenate([[0.0], np.cumsum(leg_m / leg_speed_mps)])

    leg = np.clip(np.searchsorted(waypoint_time_s, times_s, side="right") - 1, 0, len(leg_m) - 1)
    arrived = times_s >= waypoint_time_s[-1]
    waiting = times_s < vessel.depart_s
    fraction = np.where(
        arrived, 1.0, (times_s - waypoint_time_s[leg]) * leg_speed_mps[leg] / leg_m[leg]
    )
    fraction = np.where(waiting, 0.0, fraction)
    north = north_m[leg] + fraction * d_north[leg]
    east = east_m[leg] + fraction * d_east[leg]
    lat_deg, lon_deg = frame.to_geodetic(north, east)
    return VesselTrack(
        vessel=vessel,
        time_s=times_s,
        north_m=north,
        east_m=east,
        lat_deg=lat_deg,
        lon_deg=lon_deg,
        sog_kn=np.where(arrived | waiting, 0.0, np.asarray(vessel.speed_kn)[leg]),
        # AIS reports true COG; the leg's direction in the frame is a grid bearing.
        cog_deg=frame.grid_to_true_deg(leg_course_deg[leg], lat_deg, lon_deg),
    )


def _fmt(value: float) -> str:
    return f"{value:g}"


def dma_rows(track: VesselTrack, start_utc: dt.datetime) -> pd.DataFrame:
    """The track as DMA 26-column rows (text cells, formatted as DMA writes them)."""
    vessel = track.vessel
    cog = np.round(track.cog_deg, 1) % 360.0
    stamps = [_DMA_CSV.time_text(start_utc + dt.timedelta(seconds=float(t))) for t in track.time_s]
    half_length = vessel.length_m / 2.0
    half_breadth = vessel.breadth_m / 2.0
    static = {
        "Type of mobile": "Class A",
        "MMSI": str(vessel.mmsi),
        "Navigational status": _DMA_CSV.nav_status_text(vessel.nav_status),
        "ROT": "0",
        "IMO": str(vessel.imo) if vessel.imo is not None else "Unknown",
        "Callsign": vessel.callsign,
        "Name": vessel.name,
        "Ship type": vessel.ship_type,
        "Cargo type": "",
        "Width": _fmt(vessel.breadth_m),
        "Length": _fmt(vessel.length_m),
        "Type of position fixing device": "GPS",
        "Draught": _fmt(vessel.draught_m),
        "Destination": "Unknown",
        "ETA": "",
        "Data source type": "AIS",
        "A": _fmt(half_length),
        "B": _fmt(vessel.length_m - half_length),
        "C": _fmt(half_breadth),
        "D": _fmt(vessel.breadth_m - half_breadth),
    }
    frame = pd.DataFrame(
        {
            "# Timestamp": stamps,
            "Latitude": [f"{v:.6f}" for v in track.lat_deg],
            "Longitude": [f"{v:.6f}" for v in track.lon_deg],
            "SOG": [f"{v:.1f}" for v in track.sog_kn],
            "COG": [f"{v:.1f}" for v in cog],
            "Heading": [str(round(float(v)) % 360) for v in track.cog_deg],
        }
    )
    for column, value in static.items():
        frame[column] = value
    return frame[list(_DMA_CSV.columns)]


def simulate(scenario: Scenario, quiet: bool = True) -> tuple[VesselTrack, ...]:
    frame = scenario_frame(scenario)
    times_s = report_times_s(scenario)
    tracks: list[VesselTrack] = []
    with progress_bar("simulate", len(scenario.vessels), progress_enabled(quiet)) as bar:
        for vessel in scenario.vessels:
            tracks.append(simulate_vessel(vessel, frame, times_s))
            bar.advance()
    return tuple(tracks)


def default_out_path(scenario: Scenario) -> Path:
    return Path("reports") / f"simulate-{scenario.name}.csv"


def simulate_scenario(path: Path, out: Path | None = None, quiet: bool = True) -> SimulationResult:
    """Load, check and simulate a scenario; write its AIS as DMA CSV (time-ordered)."""
    scenario = load_scenario(path)
    target = out if out is not None else default_out_path(scenario)
    check_out_file(target)
    check_scenario_chart(scenario)
    tracks = simulate(scenario, quiet=quiet)
    rows = pd.concat([dma_rows(t, scenario.start_utc) for t in tracks], ignore_index=True)
    order = np.lexsort(
        (rows["MMSI"].astype(np.int64).to_numpy(), np.concatenate([t.time_s for t in tracks]))
    )
    rows = rows.iloc[order].reset_index(drop=True)
    _DMA_CSV.write(target, rows)
    return SimulationResult(scenario=scenario, out_path=target, tracks=tracks, rows=len(rows))
