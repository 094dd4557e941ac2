"""Non-finite and impossible dimensions (``inf``, ``1e400``, a 900 m ship) are "not
available": never in the statistics, never an error in the replay."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from colregs9_cli.ais.load import load_ais
from colregs9_cli.ais.schema import CANONICAL_SCHEMA
from colregs9_cli.core.vessel_defaults import vessel_dimensions
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.stats import run_stats

from fixture_files import AIS_FIXTURES, DMA26, MARINECADASTRE, ROOT

AISHUB = AIS_FIXTURES / "aishub_sample.csv"
MAPS = ROOT / "examples" / "column_maps"


def _with_length(tmp_path: Path, value: str) -> Path:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    header = lines[0].lstrip("# ").split(",")
    column = header.index("Length")
    a_column = header.index("A")
    rows = []
    for line in lines[1:]:
        fields = line.split(",")
        fields[column] = value
        fields[a_column] = ""  # the length comes from the Length column, not A+B
        rows.append(",".join(fields))
    path = tmp_path / f"length_{value}.csv"
    path.write_text("\n".join([lines[0], *rows]) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("value", ["inf", "1e400", "-inf", "900", "nan"])
def test_an_impossible_length_is_not_available(tmp_path: Path, value: str) -> None:
    path = _with_length(tmp_path, value)
    data = load_ais([path])
    assert data.ledger.balanced
    lengths = data.positions["length_m"].to_numpy(dtype=float)
    assert not np.isfinite(lengths).any()
    assert (data.dimension_reports["length_m"].dropna() <= 500.0).all()
    table = run_stats([path], out_dir=tmp_path / "stats").result.to_frame()
    counts = table.set_index("dimension")["count"]
    assert counts["length_m"] == 0  # no length is left, and nothing crashed on one
    assert counts["breadth_m"] > 0
    run_replay([path], out_dir=tmp_path / "replay", plots=False)


def test_vessel_defaults_replace_an_impossible_value() -> None:
    dims = vessel_dimensions({"length_m": 1e400, "breadth_m": 90.0, "draught_m": 5.0})
    assert dims.defaulted == ("length_m", "breadth_m")
    assert dims.draught_m == 5.0


@pytest.mark.parametrize("mmsi", ["12345678901234567890", "1e30", "-99999999999999999999"])
def test_an_mmsi_too_long_for_any_vessel_is_invalid_without_a_warning(
    tmp_path: Path, mmsi: str
) -> None:
    import warnings

    lines = DMA26.read_text(encoding="utf-8").splitlines()
    lines[1] = lines[1].replace("257739000", mmsi)
    path = tmp_path / "long_mmsi.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data = load_ais([path])
    assert data.ledger.balanced
    assert data.ledger.to_dict()["rejects_by_reason"].get("invalid_mmsi", 0) >= 1


# -- implausible dimensions: found on each reader's path, counted apart in the ledger ----------

# (length, breadth, draught) as read -> whether cleaning drops one as implausible
_DIMENSION_CASES = [
    (("288", "49", "10.5"), False),  # a real ship
    (("600", "49", "10.5"), True),  # longer than any ship
    (("288", "81", "10.5"), True),  # wider
    (("288", "49", "31"), True),  # deeper
    (("inf", "49", "10.5"), True),
    (("1e400", "49", "10.5"), True),
    (("0", "0", "0"), False),  # not available, not implausible
    (("-inf", "nan", ""), False),
    (("500", "80", "30"), False),  # the limits themselves are plausible
]


def _implausible_dma(length: str, breadth: str, draught: str) -> bool:
    from colregs9_cli.ais.dma import dma_fields

    batch = pa.table(
        {
            "mmsi": ["219000000"],
            "latitude": ["57.0"],
            "longitude": ["10.0"],
            "type of mobile": ["Class A"],
            "width": [breadth],
            "length": [length],
            "draught": [draught],
        }
    )
    return bool(dma_fields(batch, has_abcd=False).dimensions.implausible()[0])


def _implausible_dma_abcd(length: str, breadth: str, draught: str) -> bool:
    """Length as A+B, breadth as C+D (the DMA's own way when they are given)."""
    from colregs9_cli.ais.dma import dma_fields

    half = {v: str(float(v) / 2) if v not in ("", "nan") else v for v in (length, breadth)}
    batch = pa.table(
        {
            "mmsi": ["219000000"],
            "latitude": ["57.0"],
            "longitude": ["10.0"],
            "type of mobile": ["Class A"],
            "width": [""],
            "length": [""],
            "draught": [draught],
            "a": [half[length]],
            "b": [half[length]],
            "c": [half[breadth]],
            "d": [half[breadth]],
        }
    )
    return bool(dma_fields(batch, has_abcd=True).dimensions.implausible()[0])


def _implausible_marinecadastre(length: str, breadth: str, draught: str) -> bool:
    from colregs9_cli.ais.column_map import BUILTIN_MAPS
    from colregs9_cli.ais.mapped import mapped_fields

    map_ = BUILTIN_MAPS["marinecadastre"]
    values = {name: [None] for name in map_.read_columns}
    values.update(
        mmsi=["219000000"],
        lat=["57.0"],
        lon=["10.0"],
        transceiverclass=["A"],
        length=[length],
        width=[breadth],
        draft=[draught],
    )
    batch = pa.table({k: pa.array(v, pa.string()) for k, v in values.items()})
    return bool(mapped_fields(map_, batch).dimensions.implausible()[0])


def _implausible_canonical(length: str, breadth: str, draught: str) -> bool:
    """Parquet datasets and decoded NMEA: canonical float columns."""
    from colregs9_cli.ais.clean import DimensionColumns
    from colregs9_cli.ais.dimension_reports import canonical_dimensions as _canonical_dimensions

    def number(text: str) -> float | None:
        return None if text == "" else float(text)

    table = pa.table(
        {
            "length_m": pa.array([number(length)], pa.float64()),
            "breadth_m": pa.array([number(breadth)], pa.float64()),
            "draught_m": pa.array([number(draught)], pa.float64()),
        }
    )
    return bool(DimensionColumns(table, _canonical_dimensions).implausible()[0])


@pytest.mark.parametrize(
    "reader",
    [_implausible_dma, _implausible_dma_abcd, _implausible_marinecadastre, _implausible_canonical],
)
@pytest.mark.parametrize(("values", "expected"), _DIMENSION_CASES)
def test_each_reader_finds_the_dimensions_it_drops_as_implausible(
    reader, values: tuple[str, str, str], expected: bool
) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert reader(*values) is expected


def test_finding_them_leaves_the_limits_in_force() -> None:
    from colregs9_cli.ais.clean import DimensionColumns

    table = pa.table({"length_m": [600.0], "breadth_m": [10.0], "draught_m": [5.0]})
    columns = DimensionColumns(
        table, lambda t: tuple(t.column(c).to_numpy() for c in t.column_names)
    )
    assert columns.implausible().tolist() == [True]
    length, breadth, _ = columns.of_rows(np.array([0]))
    assert np.isnan(length[0]) and breadth[0] == 10.0  # still dropped when cleaned


def test_the_ledger_counts_dropped_values_apart_from_the_balance() -> None:
    from colregs9_cli.ais.ledger import DropReason, RejectReason, RejectsLedger

    ledger = RejectsLedger()
    ledger.read(10)
    ledger.use(9)
    ledger.reject(RejectReason.UNPARSEABLE)
    ledger.drop(DropReason.IMPLAUSIBLE_DIMENSION, 4, example="x.csv:3: length 600")
    part = RejectsLedger(rows_read=2, rows_used=2)
    part.drop(DropReason.IMPLAUSIBLE_DIMENSION, 2, example="y.csv:9: draught inf")
    ledger.merge(part)
    assert ledger.balanced
    payload = ledger.to_dict()
    assert payload["values_dropped"] == {"implausible_dimension": 6}
    assert payload["values_dropped_examples"]["implausible_dimension"] == [
        "x.csv:3: length 600",
        "y.csv:9: draught inf",
    ]
    assert payload["rows_rejected"] == 1
    assert RejectsLedger.from_dict(payload).to_dict() == payload
    assert "values_dropped" not in RejectsLedger().to_dict()  # unchanged without any


def test_load_counts_implausible_dimensions_in_the_ledger(tmp_path: Path) -> None:
    path = _with_length(tmp_path, "900")
    ledger = load_ais([path]).ledger
    assert ledger.balanced
    # every row past the mobile-type and MMSI checks (the duplicate too, found later)
    assert ledger.rejects == {"not_a_vessel": 1, "duplicate": 1}
    assert ledger.dropped["implausible_dimension"] == ledger.rows_read - 1
    (example, *_) = ledger.dropped_examples["implausible_dimension"]
    assert example.startswith(f"{path}:2: implausible dimension dropped (length 900 m)")


# -- every reader's path, through `colregs9 stats` and its run.json ------------------------------


def _one_row_changed(source: Path, target: Path, values: dict[str, str]) -> Path:
    """``source`` with the first data row's ``values`` (columns by name) replaced."""
    lines = source.read_text(encoding="utf-8").splitlines()
    delimiter = ";" if lines[0].count(";") > lines[0].count(",") else ","
    header = lines[0].lstrip("# ").split(delimiter)
    fields = lines[1].split(delimiter)
    for name, value in values.items():
        fields[header.index(name)] = value
    target.write_text("\n".join([lines[0], delimiter.join(fields), *lines[2:]]) + "\n")
    return target


def _dma(tmp_path: Path) -> tuple[list[str], str]:
    path = _one_row_changed(DMA26, tmp_path / "dma.csv", {"Length": "900", "A": ""})
    return [path.name], "dma.csv:2: implausible dimension dropped (length 900 m): MMSI 257739000"


def _dma_breadth_inf(tmp_path: Path) -> tuple[list[str], str]:
    path = _one_row_changed(DMA26, tmp_path / "dma_inf.csv", {"Width": "1e400", "C": ""})
    return [path.name], "dma_inf.csv:2: implausible dimension dropped (breadth inf m)"


def _marinecadastre(tmp_path: Path) -> tuple[list[str], str]:
    path = _one_row_changed(MARINECADASTRE, tmp_path / "mc.csv", {"Length": "600"})
    return [path.name], "mc.csv:2: implausible dimension dropped (length 600 m): MMSI 367752440"


def _mapped(tmp_path: Path) -> tuple[list[str], str]:
    """A column map (AISHub's): length as A+B, in metres."""
    path = _one_row_changed(AISHUB, tmp_path / "aishub.csv", {"A": "400", "B": "200"})
    return (
        [path.name, "--columns", str(MAPS / "aishub.toml")],
        "aishub.csv:2: implausible dimension dropped (length 600 m): MMSI 367752440",
    )


def _nmea(tmp_path: Path) -> tuple[list[str], str]:
    """AIS encodes A+B up to 1022 m and C+D up to 126 m: decoded, then dropped."""
    from pyais import encode_dict

    position = {"type": 1, "mmsi": 219000001, "lat": 57.05, "lon": 9.92}
    static = {"type": 5, "mmsi": 219000001, "ship_type": 70, "to_bow": 511, "to_stern": 511}
    static |= {"to_port": 4, "to_starboard": 6, "draught": 5.2, "shipname": "LONG SHIP"}
    lines = [f"{s},1384257600" for s in encode_dict(position, radio_channel="A")]
    lines += [f"{s},1384257601" for s in encode_dict(static, radio_channel="A", seq_id=1)]
    path = tmp_path / "log.nmea"
    path.write_text("\n".join(lines) + "\n")
    return [path.name], "log.nmea:2: implausible dimension dropped (length 1022 m): MMSI 219000001"


def _parquet(tmp_path: Path) -> tuple[list[str], str]:
    import pyarrow.parquet as pq

    from colregs9_cli.ais.load import load_ais as load

    table = pa.Table.from_pandas(
        load([DMA26]).positions, schema=CANONICAL_SCHEMA, preserve_index=False
    )
    lengths = table.column("length_m").to_pylist()
    lengths[0] = 600.0
    table = table.set_column(
        table.schema.get_field_index("length_m"), "length_m", pa.array(lengths)
    )
    path = tmp_path / "canonical.parquet"
    pq.write_table(table, path)
    return [path.name], "canonical.parquet: implausible dimension dropped (length 600 m): MMSI"


@pytest.mark.parametrize(
    "make", [_dma, _dma_breadth_inf, _marinecadastre, _mapped, _nmea, _parquet]
)
def test_stats_counts_the_implausible_dimension_of_each_reader(tmp_path: Path, make) -> None:  # type: ignore[no-untyped-def]
    args, example = make(tmp_path)
    done = subprocess.run(
        [sys.executable, "-m", "colregs9_cli", "stats", *args, "--out", "out", "--quiet"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        check=False,
        timeout=120,
    )
    assert done.returncode == 0 and done.stderr == "", done.stderr
    ledger = json.loads((tmp_path / "out" / "run.json").read_text())["ledger"]
    assert ledger["values_dropped"] == {"implausible_dimension": 1}
    (found,) = ledger["values_dropped_examples"]["implausible_dimension"]
    assert found.startswith(example), found
    assert ledger["rows_read"] == (
        ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
    )


def test_a_dataset_keeps_the_count_of_its_inputs(tmp_path: Path) -> None:
    from colregs9_cli.jobs.ingest import ingest

    path = _with_length(tmp_path, "900")
    ingest([path], tmp_path / "ais")
    from_dataset = load_ais([tmp_path / "ais"]).ledger
    assert from_dataset.dropped == load_ais([path]).ledger.dropped != {}
