"""Generate a synthetic DMA "aisdk" CSV (26-column 2024 layout) for benchmarks.

The file looks like a day of the Danish feed: vessels with fixed identities and dimensions
sail slow random walks over Danish waters (lat 54.5–58.0, lon 7.5–13.0), with the DMA
spellings, ``Unknown`` values and the odd lat 91 row. About 2 % of the vessels sail inside
the Limfjord box of ``queries/limfjorden.toml`` (lat 56.5–57.2, lon 8.2–10.4); the rest stay
outside it. Rows are written in blocks, so memory does not grow with the number of rows.

Never committed: write it to a temporary directory.

Usage: python tests/benchmarks/gen_dma_csv.py --rows 5000000 --out /tmp/aisdk_bench.csv
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pacsv

from colregs9_cli.ais.layouts import DMA_COLUMNS

HEADER = list(DMA_COLUMNS)

LIMFJORD_BOX = (56.5, 57.2, 8.2, 10.4)  # lat_min, lat_max, lon_min, lon_max
DANISH_WATERS = (54.5, 58.0, 7.5, 13.0)
INSIDE_FRACTION = 0.02
DAY_START_S = 1725840000  # 2024-09-09 00:00:00 UTC
BLOCK_ROWS = 500_000

SHIP_TYPES = np.array(
    ["Cargo", "Tanker", "Passenger", "Fishing", "Pleasure", "Sailing", "Tug", "Pilot", "Undefined"]
)
SHIP_TYPE_WEIGHTS = np.array([0.30, 0.12, 0.10, 0.15, 0.10, 0.08, 0.06, 0.04, 0.05])
NAV_STATUS = np.array(
    [
        "Under way using engine",
        "At anchor",
        "Moored",
        "Engaged in fishing",
        "Under way sailing",
        "Restricted manoeuverability",
        "Constrained by her draught",
        "Unknown value",
    ]
)
NAV_STATUS_WEIGHTS = np.array([0.70, 0.06, 0.12, 0.05, 0.03, 0.01, 0.01, 0.02])


def _outside_box(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    lat_lo, lat_hi, lon_lo, lon_hi = DANISH_WATERS
    box_lat_lo, box_lat_hi, box_lon_lo, box_lon_hi = LIMFJORD_BOX
    lat = rng.uniform(lat_lo, lat_hi, n)
    lon = rng.uniform(lon_lo, lon_hi, n)
    inside = (lat > box_lat_lo - 0.2) & (lat < box_lat_hi + 0.2) & (lon > box_lon_lo - 0.2)
    inside &= lon < box_lon_hi + 0.2
    # Move would-be Limfjord vessels to the Kattegat, well east of the box.
    lon[inside] = rng.uniform(box_lon_hi + 0.5, lon_hi, int(inside.sum()))
    return lat, lon


def _fleet(rng: np.random.Generator, n_vessels: int) -> dict[str, np.ndarray]:
    inside = rng.random(n_vessels) < INSIDE_FRACTION
    lat, lon = _outside_box(rng, n_vessels)
    box_lat_lo, box_lat_hi, box_lon_lo, box_lon_hi = LIMFJORD_BOX
    n_inside = int(inside.sum())
    lat[inside] = rng.uniform(box_lat_lo + 0.1, box_lat_hi - 0.1, n_inside)
    lon[inside] = rng.uniform(box_lon_lo + 0.2, box_lon_hi - 0.2, n_inside)
    ship_type = rng.choice(SHIP_TYPES, n_vessels, p=SHIP_TYPE_WEIGHTS)
    small = np.isin(ship_type, ["Fishing", "Pleasure", "Sailing", "Pilot", "Tug"])
    length = np.where(small, rng.lognormal(2.7, 0.4, n_vessels), rng.lognormal(4.6, 0.5, n_vessels))
    length = np.clip(np.round(length), 5, 400)
    breadth = np.clip(np.round(length / rng.uniform(4.5, 7.5, n_vessels)), 1, 60)
    draught = np.clip(np.round(length / rng.uniform(15, 30, n_vessels), 1), 0.1, 25)
    bow = np.clip(np.round(length * rng.uniform(0.6, 0.9, n_vessels)), 1, None)
    port = np.clip(np.round(breadth * rng.uniform(0.3, 0.7, n_vessels)), 1, None)
    no_static = rng.random(n_vessels) < 0.08  # Class B and silent vessels send no dimensions
    return {
        "mmsi": rng.choice(np.arange(201, 776), n_vessels) * 1_000_000
        + rng.integers(0, 1_000_000, n_vessels),
        "lat": lat,
        "lon": lon,
        "ship_type": np.where(no_static, "Undefined", ship_type),
        "mobile": np.where(small & (rng.random(n_vessels) < 0.5), "Class B", "Class A"),
        "length": np.where(no_static, np.nan, length),
        "breadth": np.where(no_static, np.nan, breadth),
        "draught": np.where(no_static | small, np.nan, draught),
        "a": np.where(no_static, np.nan, bow),
        "b": np.where(no_static, np.nan, length - bow),
        "c": np.where(no_static, np.nan, port),
        "d": np.where(no_static, np.nan, breadth - port),
        "imo": np.where(small, "Unknown", (9_000_000 + np.arange(n_vessels)).astype(str)),
        "callsign": np.char.add("OX", np.arange(n_vessels).astype(str)),
        "name": np.char.add("VESSEL ", np.arange(n_vessels).astype(str)),
        "destination": rng.choice(np.array(["AALBORG", "SKAGEN", "DKCPH", "Unknown"]), n_vessels),
        "sog": rng.uniform(0, 18, n_vessels),
        "cog": rng.uniform(0, 360, n_vessels),
    }


def _nullable(values: np.ndarray) -> pa.Array:
    return pa.array(values, mask=np.isnan(values))


def _block(
    rng: np.random.Generator, fleet: dict[str, np.ndarray], start_row: int, n: int, total: int
) -> pa.Table:
    vessel = rng.integers(0, len(fleet["mmsi"]), n)
    seconds = DAY_START_S + (np.arange(start_row, start_row + n) * 86_400) // total
    drift = (seconds - DAY_START_S) / 86_400.0
    lat = fleet["lat"][vessel] + 0.05 * np.sin(drift * 6.0 + vessel) + rng.normal(0, 2e-4, n)
    lon = fleet["lon"][vessel] + 0.08 * np.cos(drift * 5.0 + vessel) + rng.normal(0, 2e-4, n)
    no_position = rng.random(n) < 0.002
    lat = np.where(no_position, 91.0, np.round(lat, 6))
    lon = np.where(no_position, 0.0, np.round(lon, 6))
    sog = np.round(np.clip(fleet["sog"][vessel] + rng.normal(0, 0.3, n), 0, 40), 1)
    cog = np.round((fleet["cog"][vessel] + rng.normal(0, 3, n)) % 360, 1)
    timestamps = pc.strftime(pa.array(seconds.astype("datetime64[s]")), format="%d/%m/%Y %H:%M:%S")
    nav_status = rng.choice(NAV_STATUS, n, p=NAV_STATUS_WEIGHTS)
    columns = [
        timestamps,
        pa.array(fleet["mobile"][vessel]),
        pa.array(fleet["mmsi"][vessel]),
        pa.array(lat),
        pa.array(lon),
        pa.array(nav_status),
        pa.array(np.round(rng.normal(0, 2, n), 1)),
        pa.array(sog),
        pa.array(cog),
        pa.array(np.round(cog).astype(np.int64) % 360),
        pa.array(fleet["imo"][vessel]),
        pa.array(fleet["callsign"][vessel]),
        pa.array(fleet["name"][vessel]),
        pa.array(fleet["ship_type"][vessel]),
        pa.nulls(n, pa.string()),
        _nullable(fleet["breadth"][vessel]),
        _nullable(fleet["length"][vessel]),
        pa.array(np.full(n, "GPS")),
        _nullable(fleet["draught"][vessel]),
        pa.array(fleet["destination"][vessel]),
        pa.nulls(n, pa.string()),
        pa.array(np.full(n, "AIS")),
        _nullable(fleet["a"][vessel]),
        _nullable(fleet["b"][vessel]),
        _nullable(fleet["c"][vessel]),
        _nullable(fleet["d"][vessel]),
    ]
    return pa.table(columns, names=HEADER)


def generate(path: Path, rows: int = 5_000_000, n_vessels: int = 4_000, seed: int = 9) -> Path:
    """Write ``rows`` DMA CSV rows to ``path`` (in blocks); returns the path."""
    rng = np.random.default_rng(seed)
    fleet = _fleet(rng, n_vessels)
    # pyarrow quotes header names; DMA files have a bare header line.
    options = pacsv.WriteOptions(include_header=False, quoting_style="none")
    with path.open("wb") as sink:
        sink.write((",".join(HEADER) + "\n").encode())
        writer: pacsv.CSVWriter | None = None
        for start in range(0, rows, BLOCK_ROWS):
            table = _block(rng, fleet, start, min(BLOCK_ROWS, rows - start), rows)
            if writer is None:
                writer = pacsv.CSVWriter(sink, table.schema, write_options=options)
            writer.write_table(table)
        if writer is not None:
            writer.close()
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=5_000_000)
    parser.add_argument("--vessels", type=int, default=4_000)
    parser.add_argument("--seed", type=int, default=9)
    parser.add_argument("--out", type=Path, default=None, help="default: a new temp directory")
    args = parser.parse_args()
    out = args.out or Path(tempfile.mkdtemp(prefix="colregs9-bench-")) / "aisdk_bench.csv"
    started = time.perf_counter()
    generate(out, rows=args.rows, n_vessels=args.vessels, seed=args.seed)
    elapsed = time.perf_counter() - started
    size_mb = out.stat().st_size / 1e6
    print(f"wrote {args.rows:,} rows, {size_mb:,.0f} MB, to {out} in {elapsed:.1f} s")


if __name__ == "__main__":
    main()
