"""Build "a national day at 2013 density": the real 5-minute DMA NMEA sample, dead-reckoned.

The input is ``fixtures/ais/dma_nmea_2013-11-12_5min.txt.gz`` (the Danish Maritime
Authority's national feed, 2013-11-12 12:00-12:05 UTC), decoded with the project's own
loader (``load_ais``). Every vessel of the sample is kept, with its MMSI, mobile type,
navigational status, ship type, name, call sign, IMO and dimensions (where the five
minutes carried them; most vessels sent no static report in that time), and reports over
the chosen duration at its own rate:

- report interval: the median interval between its reports in the sample, but never more
  often than it was heard (the sample's span over its number of reports): a vessel heard
  twice, 10 s apart, reports every 150 s, not every 10 s; a vessel heard once, every 300 s.
  This keeps the sample's density: an hour holds about 12 times the sample's rows;
- moving vessels (median SOG >= ``--min-sog-kn``, 0.5 kn) start where the sample first saw
  them and go on along their course at their speed. Every ``SUB_STEP_S`` (30 s) the course
  takes a random walk step (0.15 deg per root second: about 9 deg in an hour) and the speed
  an Ornstein-Uhlenbeck step towards the vessel's own (standard deviation 0.3 kn, 15 min
  correlation time, never below the threshold). They reflect (turn back) at the walls of
  the box: the sample's own bounding box by default (lat 54.09-58.00, lon 7.50-16.15), or
  the Danish box (``--box danish``: lat 54.5-58.0, lon 7.5-15.5). The reflection is a
  fold of the unconstrained track, so a vessel crossing a wall between reports is placed
  correctly and its course mirrored. Land is ignored;
- stationary vessels report around their median position in the sample;
- every report has GPS noise (3 m standard deviation north and east), COG noise (1 deg),
  SOG noise (0.1 kn), and a heading (the course plus the vessel's own offset between
  heading and COG in the sample) where the vessel sent headings.

The day starts at ``--start`` (default 2013-11-12 00:00:00 UTC, so that a 24 h day stays
on one date). The work is vectorised over vessels and done in time blocks of
``BLOCK_S`` (600 s), each written out as soon as it is made, so memory does not grow with
the duration. The output is a DMA 26-column CSV (``colregs9_cli.ais.layouts.DMA_COLUMNS``,
``dd/mm/yyyy HH:MM:SS`` timestamps, static data on every row, ``Unknown`` and empty for
values not known), sorted by time then MMSI; ``--gzip`` (or a ``.gz`` name) compresses it.

Never committed: write it to a temporary directory.

Usage: python tests/benchmarks/gen_national_day.py --hours 24 --out /tmp/national_24h.csv
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime as dt
import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv

from colregs9_cli.ais.layouts import DMA_COLUMNS
from colregs9_cli.vessels import NAV_STATUS_CODES

ROOT = Path(__file__).resolve().parents[2]
SAMPLE_NAME = "dma_nmea_2013-11-12_5min.txt.gz"
SAMPLE_CANDIDATES = (
    ROOT / "fixtures" / "ais" / SAMPLE_NAME,
    ROOT.parent / "shared" / "data" / SAMPLE_NAME,
)
DANISH_BOX = (54.5, 58.0, 7.5, 15.5)  # lat_min, lat_max, lon_min, lon_max
DEFAULT_START = dt.datetime(2013, 11, 12, tzinfo=dt.UTC)

BLOCK_S = 600  # one written block (about 50,000 rows at 2013 density)
SUB_STEP_S = 30.0  # course and speed are constant within a sub-step
COURSE_WALK_DEG_PER_SQRT_S = 0.15
SPEED_SD_KN = 0.3
SPEED_TAU_S = 900.0
GPS_SD_M = 3.0
COG_SD_DEG = 1.0
SOG_SD_KN = 0.1
HEADING_SD_DEG = 1.0

METRES_PER_DEG_LAT = 111_320.0
MPS_PER_KN = 1852.0 / 3600.0
# DMA's spellings of the navigational status (DESIGN §4); the readers map both back.
DMA_NAV_STATUS = {**NAV_STATUS_CODES, 3: "Restricted manoeuverability"}
HEADER = list(DMA_COLUMNS)


def find_sample() -> Path:
    for path in SAMPLE_CANDIDATES:
        if path.exists():
            return path
    raise SystemExit(f"no {SAMPLE_NAME} in {', '.join(str(p.parent) for p in SAMPLE_CANDIDATES)}")


@dataclass
class Fleet:
    """One entry per vessel of the sample (numpy arrays of equal length)."""

    mmsi: np.ndarray
    interval_s: np.ndarray
    phase_s: np.ndarray
    moving: np.ndarray
    lat: np.ndarray  # start (moving) or median (stationary) position
    lon: np.ndarray
    sog_kn: np.ndarray  # median SOG
    cog_deg: np.ndarray  # course: moving vessels' start course; stationary: median COG or NaN
    heading_offset_deg: np.ndarray  # heading - COG (moving), heading (stationary); NaN: none
    has_rot: np.ndarray
    static: dict[str, pa.Array]  # DMA text and number columns, one entry per vessel
    sample_rows: int
    sample_span_s: float
    box: tuple[float, float, float, float]


def _circular_median_deg(values: np.ndarray) -> float:
    """A robust central angle: the circular mean of the values (NaN if none)."""
    values = values[~np.isnan(values)]
    if len(values) == 0:
        return float("nan")
    radians = np.radians(values)
    return float(np.degrees(np.arctan2(np.sin(radians).mean(), np.cos(radians).mean())) % 360)


def _first_valid(values: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> list[object]:
    """Per group [start, end) of an object array: the last non-null value, else None."""
    out: list[object] = []
    for start, end in zip(starts, ends, strict=True):
        chosen = None
        for value in values[start:end][::-1]:
            if not pd.isna(value):
                chosen = value
                break
        out.append(chosen)
    return out


def load_fleet(sample: Path, min_sog_kn: float, box_name: str) -> Fleet:
    """Decode the sample with the project's loader; one entry per vessel."""
    from colregs9_cli.ais.load import load_ais

    positions = load_ais([sample], quiet=True).positions  # sorted by (mmsi, timestamp)
    epoch = pd.Timestamp(0, tz="UTC")
    t = (positions["timestamp"] - epoch).dt.total_seconds().to_numpy()
    t0 = float(t.min())
    span_s = float(t.max() - t0)
    mmsi_all = positions["mmsi"].to_numpy()
    mmsi, starts, counts = np.unique(mmsi_all, return_index=True, return_counts=True)
    ends = starts + counts
    lat_all = positions["lat_deg"].to_numpy(float)
    lon_all = positions["lon_deg"].to_numpy(float)
    sog_all = positions["sog_kn"].to_numpy(float, na_value=np.nan)
    cog_all = positions["cog_deg"].to_numpy(float, na_value=np.nan)
    heading_all = positions["heading_deg"].to_numpy(float, na_value=np.nan)
    rot_all = positions["rot_deg_per_min"].to_numpy(float, na_value=np.nan)

    n = len(mmsi)
    interval = np.empty(n)
    phase = np.empty(n)
    moving = np.zeros(n, bool)
    lat, lon = np.empty(n), np.empty(n)
    sog, cog, offset = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    has_rot = np.zeros(n, bool)
    for i, (start, end) in enumerate(zip(starts, ends, strict=True)):
        times = t[start:end]
        median_gap = float(np.median(np.diff(times))) if end - start > 1 else span_s
        interval[i] = max(median_gap, span_s / (end - start), 1.0)
        phase[i] = (times[0] - t0) % interval[i]
        speeds = sog_all[start:end]
        sog[i] = np.nanmedian(speeds) if np.isfinite(speeds).any() else np.nan
        moving[i] = bool(sog[i] >= min_sog_kn)
        courses = cog_all[start:end]
        headings = heading_all[start:end]
        has_rot[i] = bool(np.isfinite(rot_all[start:end]).any())
        if moving[i]:
            lat[i], lon[i] = lat_all[start], lon_all[start]
            course = _circular_median_deg(courses)
            if np.isnan(course):
                course = _circular_median_deg(headings)
            cog[i] = course  # NaN: drawn at random below
            both = np.isfinite(courses) & np.isfinite(headings)
            if both.any():
                offset[i] = _circular_median_deg((headings[both] - courses[both]) % 360)
                offset[i] = (offset[i] + 180) % 360 - 180
        else:
            lat[i], lon[i] = np.median(lat_all[start:end]), np.median(lon_all[start:end])
            cog[i] = _circular_median_deg(courses)
            offset[i] = _circular_median_deg(headings)

    if box_name == "danish":
        box = DANISH_BOX
    else:
        box = (
            float(lat_all.min()),
            float(lat_all.max()),
            float(lon_all.min()),
            float(lon_all.max()),
        )

    def text(column: str, missing: str) -> pa.Array:
        values = _first_valid(positions[column].to_numpy(object), starts, ends)
        return pa.array([missing if v is None else str(v) for v in values], pa.string())

    def whole(column: str) -> pa.Array:
        values = _first_valid(positions[column].to_numpy(object), starts, ends)
        return pa.array([None if v is None else round(float(v)) for v in values], pa.int64())

    nav_codes = _first_valid(positions["nav_status"].to_numpy(object), starts, ends)
    imo = _first_valid(positions["imo"].to_numpy(object), starts, ends)
    draught = _first_valid(positions["draught_m"].to_numpy(object), starts, ends)
    static = {
        "Type of mobile": text("mobile_type", "Class A"),
        "Navigational status": pa.array(
            [
                DMA_NAV_STATUS.get(int(c), "Unknown value") if c is not None else "Unknown value"
                for c in nav_codes
            ]
        ),
        "IMO": pa.array(["Unknown" if v is None else str(int(v)) for v in imo]),
        "Callsign": text("callsign", "Unknown"),
        "Name": text("name", ""),
        "Ship type": text("ship_type", "Undefined"),
        "Width": whole("breadth_m"),
        "Length": whole("length_m"),
        "Draught": pa.array(
            [None if v is None else round(float(v), 1) for v in draught], pa.float64()
        ),
    }
    return Fleet(
        mmsi=mmsi,
        interval_s=interval,
        phase_s=phase,
        moving=moving,
        lat=lat,
        lon=lon,
        sog_kn=sog,
        cog_deg=cog,
        heading_offset_deg=offset,
        has_rot=has_rot,
        static=static,
        sample_rows=len(positions),
        sample_span_s=span_s,
        box=box,
    )


def _fold(x: np.ndarray, lo: float, hi: float) -> tuple[np.ndarray, np.ndarray]:
    """Reflect an unconstrained coordinate into [lo, hi]; +1/-1 where it runs as/against x."""
    width = hi - lo
    u = np.mod(x - lo, 2 * width)
    back = u > width
    return lo + np.where(back, 2 * width - u, u), np.where(back, -1.0, 1.0)


def _report_times(fleet: Fleet, t0: float, t1: float) -> tuple[np.ndarray, np.ndarray]:
    """Every vessel's reports in [t0, t1): vessel indices and times (s from the day's start)."""
    first = np.ceil((t0 - fleet.phase_s) / fleet.interval_s).astype(np.int64)
    stop = np.ceil((t1 - fleet.phase_s) / fleet.interval_s).astype(np.int64)
    counts = np.maximum(stop - first, 0)
    vessel = np.repeat(np.arange(len(counts)), counts)
    offsets = np.arange(len(vessel)) - np.repeat(np.cumsum(counts) - counts, counts)
    times = fleet.phase_s[vessel] + (first[vessel] + offsets) * fleet.interval_s[vessel]
    return vessel, np.clip(times, t0, np.nextafter(t1, t0))


class DayWriter:
    """Dead-reckons the fleet block by block and writes DMA CSV rows."""

    def __init__(self, fleet: Fleet, seed: int, min_sog_kn: float, start: dt.datetime) -> None:
        self.fleet = fleet
        self.rng = np.random.default_rng(seed)
        self.min_sog_kn = min_sog_kn
        self.start_s = int(start.timestamp())
        n = len(fleet.mmsi)
        # The unconstrained ("free") track of each moving vessel; folded into the box.
        self.free_lat = fleet.lat.copy()
        self.free_lon = fleet.lon.copy()
        no_course = np.isnan(fleet.cog_deg)
        self.course = np.where(no_course, self.rng.uniform(0, 360, n), fleet.cog_deg)
        self.base_sog = np.where(fleet.moving, np.nan_to_num(fleet.sog_kn), 0.0)
        self.sog = self.base_sog.copy()

    def _sub_steps(self, count: int) -> tuple[np.ndarray, ...]:
        """Start (free) positions, velocities (deg/s), true course and SOG per sub-step."""
        fleet, rng = self.fleet, self.rng
        n = len(fleet.mmsi)
        lat_min, lat_max = fleet.box[:2]
        shape = (n, count)
        start_lat, start_lon = np.empty(shape), np.empty(shape)
        v_lat, v_lon = np.empty(shape), np.empty(shape)
        course, sog = np.empty(shape), np.empty(shape)
        keep = np.exp(-SUB_STEP_S / SPEED_TAU_S)
        for s in range(count):
            start_lat[:, s], start_lon[:, s] = self.free_lat, self.free_lon
            course[:, s], sog[:, s] = self.course, self.sog
            lat_now, _ = _fold(self.free_lat, lat_min, lat_max)
            speed_mps = np.where(fleet.moving, self.sog * MPS_PER_KN, 0.0)
            radians = np.radians(self.course)
            v_lat[:, s] = speed_mps * np.cos(radians) / METRES_PER_DEG_LAT
            v_lon[:, s] = (
                speed_mps * np.sin(radians) / (METRES_PER_DEG_LAT * np.cos(np.radians(lat_now)))
            )
            self.free_lat = self.free_lat + v_lat[:, s] * SUB_STEP_S
            self.free_lon = self.free_lon + v_lon[:, s] * SUB_STEP_S
            self.course = (
                self.course + rng.normal(0, COURSE_WALK_DEG_PER_SQRT_S * np.sqrt(SUB_STEP_S), n)
            ) % 360
            noise = rng.normal(0, SPEED_SD_KN * np.sqrt(1 - keep**2), n)
            self.sog = self.base_sog + keep * (self.sog - self.base_sog) + noise
            self.sog = np.where(fleet.moving, np.maximum(self.sog, self.min_sog_kn), 0.0)
        return start_lat, start_lon, v_lat, v_lon, course, sog

    def block(self, t0: float, t1: float) -> pa.Table:
        """The rows of [t0, t1) (seconds from the day's start), sorted by time and MMSI."""
        fleet, rng = self.fleet, self.rng
        count = int(np.ceil((t1 - t0) / SUB_STEP_S))
        start_lat, start_lon, v_lat, v_lon, course_s, sog_s = self._sub_steps(count)
        vessel, times = _report_times(fleet, t0, t1)
        seconds = np.floor(times).astype(np.int64)
        order = np.lexsort((fleet.mmsi[vessel], seconds))
        vessel, times, seconds = vessel[order], times[order], seconds[order]
        n = len(vessel)
        step = np.minimum(((times - t0) // SUB_STEP_S).astype(np.int64), count - 1)
        into = times - t0 - step * SUB_STEP_S
        lat_min, lat_max, lon_min, lon_max = fleet.box
        lat, sign_north = _fold(
            start_lat[vessel, step] + v_lat[vessel, step] * into, lat_min, lat_max
        )
        lon, sign_east = _fold(
            start_lon[vessel, step] + v_lon[vessel, step] * into, lon_min, lon_max
        )
        moving = fleet.moving[vessel]
        # Stationary vessels stay at their median position, inside the box or not.
        lat = np.where(moving, lat, fleet.lat[vessel])
        lon = np.where(moving, lon, fleet.lon[vessel])
        lat = lat + rng.normal(0, GPS_SD_M, n) / METRES_PER_DEG_LAT
        lon = lon + rng.normal(0, GPS_SD_M, n) / (METRES_PER_DEG_LAT * np.cos(np.radians(lat)))
        radians = np.radians(course_s[vessel, step])
        true_course = (
            np.degrees(np.arctan2(np.sin(radians) * sign_east, np.cos(radians) * sign_north)) % 360
        )
        still_cog = fleet.cog_deg[vessel] + rng.normal(0, 30.0, n)
        cog = np.where(moving, true_course + rng.normal(0, COG_SD_DEG, n), still_cog) % 360
        sog = np.where(
            moving,
            sog_s[vessel, step] + rng.normal(0, SOG_SD_KN, n),
            np.nan_to_num(fleet.sog_kn[vessel]) + np.abs(rng.normal(0, SOG_SD_KN, n)),
        )
        sog = np.clip(sog, 0.0, 102.2)
        offset = fleet.heading_offset_deg[vessel]
        heading = np.where(moving, true_course + offset, offset) + rng.normal(0, HEADING_SD_DEG, n)
        heading = np.round(heading) % 360
        stamps = pc.strftime(
            pa.array((self.start_s + seconds).astype("datetime64[s]")), format="%d/%m/%Y %H:%M:%S"
        )
        take = pa.array(vessel)
        static = {name: values.take(take) for name, values in fleet.static.items()}
        columns = {
            "# Timestamp": stamps,
            "Type of mobile": static["Type of mobile"],
            "MMSI": pa.array(fleet.mmsi[vessel]),
            "Latitude": pa.array(np.round(lat, 6)),
            "Longitude": pa.array(np.round(lon, 6)),
            "Navigational status": static["Navigational status"],
            "ROT": pa.array(np.zeros(n), mask=~fleet.has_rot[vessel]),
            "SOG": pa.array(np.round(sog, 1)),
            "COG": pa.array(np.round(cog, 1) % 360, mask=np.isnan(cog)),
            "Heading": pa.array(heading.astype(np.float64), mask=np.isnan(heading)).cast(
                pa.int64()
            ),
            "IMO": static["IMO"],
            "Callsign": static["Callsign"],
            "Name": static["Name"],
            "Ship type": static["Ship type"],
            "Cargo type": pa.nulls(n, pa.string()),
            "Width": static["Width"],
            "Length": static["Length"],
            "Type of position fixing device": pa.array(np.full(n, "GPS")),
            "Draught": static["Draught"],
            "Destination": pa.array(np.full(n, "Unknown")),
            "ETA": pa.nulls(n, pa.string()),
            "Data source type": pa.array(np.full(n, "AIS")),
            "A": pa.nulls(n, pa.int64()),
            "B": pa.nulls(n, pa.int64()),
            "C": pa.nulls(n, pa.int64()),
            "D": pa.nulls(n, pa.int64()),
        }
        return pa.table([columns[name] for name in HEADER], names=HEADER)


@dataclass(frozen=True)
class DaySummary:
    path: Path
    hours: float
    rows: int
    vessels: int
    moving: int
    sample_rows: int
    sample_span_s: float
    seconds: float


def generate(
    out: Path,
    hours: float,
    seed: int = 15,
    sample: Path | None = None,
    compress: bool = False,
    box: str = "sample",
    min_sog_kn: float = 0.5,
    start: dt.datetime = DEFAULT_START,
) -> DaySummary:
    """Write the day to ``out`` (gzip if ``compress`` or a ``.gz`` name); returns its summary."""
    started = time.perf_counter()
    fleet = load_fleet(sample or find_sample(), min_sog_kn, box)
    writer = DayWriter(fleet, seed, min_sog_kn, start)
    total_s = hours * 3600.0
    rows = 0
    seen = np.zeros(len(fleet.mmsi), bool)
    # pyarrow quotes header names; DMA files have a bare header line. Names and call signs
    # decoded from NMEA hold no commas or quotes (six-bit text, checked by the readers).
    options = pacsv.WriteOptions(include_header=False, quoting_style="none")
    out.parent.mkdir(parents=True, exist_ok=True)
    compress = compress or out.suffix == ".gz"
    sink = pa.CompressedOutputStream(str(out), "gzip") if compress else pa.OSFile(str(out), "wb")
    with sink:
        sink.write((",".join(HEADER) + "\n").encode())
        csv_writer: pacsv.CSVWriter | None = None
        t0 = 0.0
        while t0 < total_s:
            t1 = min(t0 + BLOCK_S, total_s)
            table = writer.block(t0, t1)
            if csv_writer is None:
                csv_writer = pacsv.CSVWriter(sink, table.schema, write_options=options)
            csv_writer.write_table(table)
            rows += table.num_rows
            seen[np.searchsorted(fleet.mmsi, table.column("MMSI").to_numpy())] = True
            t0 = t1
        if csv_writer is not None:
            csv_writer.close()
    return DaySummary(
        path=out,
        hours=hours,
        rows=rows,
        vessels=int(seen.sum()),
        moving=int((seen & fleet.moving).sum()),
        sample_rows=fleet.sample_rows,
        sample_span_s=fleet.sample_span_s,
        seconds=time.perf_counter() - started,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=1.0, help="duration of the day (h)")
    parser.add_argument("--out", type=Path, default=None, help="default: a new temp directory")
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--gzip", action="store_true", help="gzip the CSV (also for a .gz name)")
    parser.add_argument("--sample", type=Path, default=None, help=f"default: {SAMPLE_NAME}")
    parser.add_argument(
        "--box", choices=("sample", "danish"), default="sample", help="walls the vessels turn at"
    )
    parser.add_argument("--min-sog-kn", type=float, default=0.5, help="moving vessels: median SOG")
    parser.add_argument(
        "--start",
        type=dt.datetime.fromisoformat,
        default=DEFAULT_START,
        help="UTC start of the day, ISO 8601 (default 2013-11-12T00:00:00+00:00)",
    )
    parser.add_argument("--json", type=Path, default=None, help="also write the summary here")
    args = parser.parse_args()
    if args.hours <= 0:
        parser.error("--hours must be positive")
    name = f"national_{args.hours:g}h.csv" + (".gz" if args.gzip else "")
    out = args.out or Path(tempfile.mkdtemp(prefix="colregs9-bench-")) / name
    start = args.start if args.start.tzinfo else args.start.replace(tzinfo=dt.UTC)
    summary = generate(
        out, args.hours, args.seed, args.sample, args.gzip, args.box, args.min_sog_kn, start
    )
    per_sample = summary.rows / summary.sample_rows
    print(
        f"wrote {summary.rows:,} rows ({per_sample:.1f}x the sample's {summary.sample_rows:,}"
        f" in {summary.sample_span_s:.0f} s), {summary.vessels:,} vessels, {summary.moving:,}"
        f" moving, {out.stat().st_size / 1e6:,.0f} MB, to {out} in {summary.seconds:.1f} s"
    )
    if args.json is not None:
        record = {**dataclasses.asdict(summary), "path": str(out), "bytes": out.stat().st_size}
        args.json.write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
