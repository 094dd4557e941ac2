"""AIS's A, B, C, D through the canonical schema (``to_bow_m`` ... ``to_starboard_m``): one
cleaning (``clean.offset_parts``) on every reader's path, the four from one report, old
datasets read with them null, and the hull distance placing the antenna where AIS says."""

from __future__ import annotations

import gzip
import json
import math
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import given
from hypothesis import strategies as st
from pyais import encode_dict

from colregs9_cli.ais.clean import offset_parts
from colregs9_cli.ais.dataset_scan import MANIFEST_NAME, manifest_schema
from colregs9_cli.ais.dma import dma_canonical
from colregs9_cli.ais.layouts import normalise_column
from colregs9_cli.ais.ledger import RejectsLedger
from colregs9_cli.ais.load import load_ais
from colregs9_cli.ais.nmea import read_nmea
from colregs9_cli.ais.schema import ANTENNA_OFFSETS, CANONICAL_COLUMNS, CANONICAL_SCHEMA
from colregs9_cli.core.hull import HullOffsets, centred_offsets
from colregs9_cli.core.pair_audit import hull_offsets, least_hull_separation_m
from colregs9_cli.core.tracks import ANTENNA_OFFSET_COLUMNS, STATIC_COLUMNS, latest_statics
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import InputFileError
from colregs9_cli.geo import sail
from colregs9_cli.jobs.ingest import ingest
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.simulate import simulate_scenario
from colregs9_cli.vessels import MAX_BREADTH_M, MAX_LENGTH_M

from fixture_files import (
    AIS_FIXTURES,
    DMA22,
    DMA26,
    GREENHOPPER_QUERY,
    MARINECADASTRE,
    NMEA,
    ROOT,
    SCENARIOS,
)

NAN = math.nan
NOON = 1_384_257_600  # 2013-11-12 12:00:00 UTC
PARTS = list(ANTENNA_OFFSETS)


def _parts(*values: float) -> tuple[np.ndarray, ...]:
    return tuple(np.array([v], dtype=float) for v in values)


def _cleaned(a: float, b: float, c: float, d: float) -> tuple[float, ...]:
    """(A, B, C, D, length, breadth) of one row as ``offset_parts`` cleans it."""
    got = offset_parts(*_parts(a, b, c, d))
    return tuple(
        float(v[0])
        for v in (
            got.to_bow_m,
            got.to_stern_m,
            got.to_port_m,
            got.to_starboard_m,
            got.length_m,
            got.breadth_m,
        )
    )


def _same(got: tuple[float, ...], want: tuple[float, ...]) -> bool:
    return all((math.isnan(g) and math.isnan(w)) or g == w for g, w in zip(got, want, strict=True))


# -- offset_parts: the one cleaning ---------------------------------------------------------


@pytest.mark.parametrize(
    ("raw", "want"),
    [
        ((78, 12, 7, 7), (78, 12, 7, 7, 90, 14)),  # all four reported
        # ITU-R M.1371: A = C = 0 with B, D > 0: no reference point, B long and D wide
        ((0, 90, 0, 14), (NAN, NAN, NAN, NAN, 90, 14)),
        ((0, 90, 5, 9), (NAN, 90, 5, 9, NAN, 14)),  # one-sided zero: A alone not available
        ((30, 0, 4, 0), (30, NAN, 4, NAN, NAN, NAN)),
        ((0, 0, 0, 0), (NAN, NAN, NAN, NAN, NAN, NAN)),  # all "not available"
        ((-3, NAN, 4, 6), (NAN, NAN, 4, 6, NAN, 10)),
        ((0, 0, 0, 14), (NAN, NAN, NAN, 14, NAN, NAN)),  # B = 0: not the A = C = 0 case
        # A lone part beyond what ships have is the (implausible) length, not kept silently
        ((600, 0, 4, 6), (600, NAN, 4, 6, 600, 10)),
        ((10, math.inf, 4, 6), (10, math.inf, 4, 6, math.inf, 10)),
        ((400, 200, 30, 60), (400, 200, 30, 60, 600, 90)),  # dropped later, with its row
    ],
)
def test_offset_parts_hand_worked(raw: tuple[float, ...], want: tuple[float, ...]) -> None:
    assert _same(_cleaned(*map(float, raw)), tuple(map(float, want)))


_PART = st.one_of(
    st.sampled_from([0.0, -1.0, NAN, math.inf, 511.0, 63.0]),
    st.floats(min_value=-50.0, max_value=700.0, allow_nan=False),
)


@given(_PART, _PART, _PART, _PART)
def test_offset_parts_properties(a: float, b: float, c: float, d: float) -> None:
    bow, stern, port, starboard, length, breadth = _cleaned(a, b, c, d)
    for part in (bow, stern, port, starboard, length, breadth):
        assert math.isnan(part) or part > 0.0  # never a 0 or a negative
    if a == 0.0 and c == 0.0 and b > 0.0 and d > 0.0:
        assert all(math.isnan(p) for p in (bow, stern, port, starboard))
        assert (length, breadth) == (b, d)
        return
    for raw, part in zip((a, b, c, d), (bow, stern, port, starboard), strict=True):
        assert part == raw if raw > 0.0 else math.isnan(part)
    for first, second, total, limit in (
        (bow, stern, length, MAX_LENGTH_M),
        (port, starboard, breadth, MAX_BREADTH_M),
    ):
        if not (math.isnan(first) or math.isnan(second)):
            assert total == first + second
        elif math.isnan(first) and math.isnan(second):
            assert math.isnan(total)
        else:  # a lone part gives a length only when it alone is beyond the limit
            lone = second if math.isnan(first) else first
            assert (total == lone) if lone > limit else math.isnan(total)


# -- each reader ------------------------------------------------------------------------------


def test_dma_26_columns_give_the_parts_of_the_file() -> None:
    raw = pd.read_csv(DMA26)
    raw = raw[(raw["Type of mobile"] != "AtoN") & (raw["Latitude"] <= 90)].drop_duplicates()
    data = load_ais([DMA26])
    assert data.ledger.balanced
    got = data.positions.set_index("mmsi")
    want = raw.set_index("MMSI")
    assert sorted(got.index) == sorted(want.index)
    for part, column in zip(PARTS, "ABCD", strict=True):
        expected = want[column].where(want[column] > 0).astype(float)
        pd.testing.assert_series_equal(
            got[part].sort_index(), expected.sort_index(), check_names=False
        )
    both = want["A"].notna() & want["B"].notna()
    assert (got.loc[both[both].index, "length_m"] == (want["A"] + want["B"])[both]).all()

    # A static report (no position) whose D is missing: the breadth is the Width column, the
    # parts stay as reported.
    frame = pd.read_csv(DMA26, dtype=str, keep_default_na=False)
    frame.columns = [normalise_column(c) for c in frame.columns]
    table, _ = dma_canonical(pa.Table.from_pandas(frame, preserve_index=False), has_abcd=True)
    static = table.to_pandas().set_index("mmsi").loc[219012931]
    assert static[PARTS].tolist()[:3] == [7.0, 5.0, 4.0]
    assert np.isnan(static["to_starboard_m"])
    assert static[["length_m", "breadth_m"]].tolist() == [12.0, 4.0]


@pytest.mark.parametrize("path", [DMA22, MARINECADASTRE], ids=["dma22", "marinecadastre"])
def test_layouts_without_a_b_c_d_give_null_parts(path: Path) -> None:
    positions = load_ais([path]).positions
    assert list(positions.columns) == list(CANONICAL_COLUMNS)
    assert positions[PARTS].isna().all().all()
    assert positions["length_m"].notna().any()


def test_exactearth_parts_come_from_its_dimension_columns() -> None:
    positions = load_ais([AIS_FIXTURES / "exactearth_sample.csv"]).positions
    rows = positions.set_index("mmsi")
    # Its message 5 rows (no position) are static reports; the positions carry no static
    # fields, so the parts are read on the file's static rows: stats counts them.
    assert rows[PARTS].isna().all().all()
    from colregs9_cli.ais.column_map import BUILTIN_MAPS
    from colregs9_cli.ais.mapped import mapped_canonical

    map_ = BUILTIN_MAPS["exactearth"]
    frame = pd.read_csv(AIS_FIXTURES / "exactearth_sample.csv", dtype=str)
    frame.columns = [c.lower() for c in frame.columns]
    table, _ = mapped_canonical(map_, pa.Table.from_pandas(frame, preserve_index=False))
    statics = table.to_pandas().set_index("mmsi").loc[lambda f: f[PARTS].notna().any(axis=1)]
    assert statics.loc[636021061, PARTS].tolist() == [146.0, 62.0, 15.0, 15.0]
    assert statics.loc[636021061, ["length_m", "breadth_m"]].tolist() == [208.0, 30.0]
    # C = D = 0: not available; A and B kept, no breadth.
    assert statics.loc[367679550, PARTS].tolist()[:2] == [15.0, 7.0]
    assert statics.loc[367679550, ["to_port_m", "to_starboard_m", "breadth_m"]].isna().all()
    assert 367752440 not in statics.index  # 0, 0, 0, 0


def test_a_column_map_reads_a_b_c_d(tmp_path: Path) -> None:
    source = AIS_FIXTURES / "aishub_sample.csv"
    data = load_ais([source], fmt=f"columns:{ROOT / 'examples' / 'column_maps' / 'aishub.toml'}")
    rows = data.positions.set_index("mmsi")
    assert rows.loc[636021061, PARTS].tolist() == [146.0, 62.0, 15.0, 15.0]
    assert rows.loc[367752440, PARTS].isna().all()  # 0, 0, 0, 0


def test_a_map_cannot_name_the_canonical_offsets_besides_to_bow(tmp_path: Path) -> None:
    """A map names A ``to_bow`` (as before the schema had it); ``to_bow_m`` is not a target,
    so one column cannot be filled twice."""
    from colregs9_cli.ais.column_map import TARGETS

    assert "to_bow" in TARGETS and "to_bow_m" not in TARGETS


def test_nmea_fixture_positions_take_the_four_of_one_static_report() -> None:
    ledger = RejectsLedger()
    with gzip.open(NMEA, "rt", encoding="utf-8") as stream:
        (batch,) = read_nmea((line.rstrip("\n") for line in stream), NMEA.name, ledger)
    statics = batch.statics.to_pandas()
    reported = statics.dropna(subset=PARTS, how="all")
    assert len(reported) >= 90  # 96 of the fixture's 130 static reports have some part
    assert (reported[PARTS].fillna(1.0) > 0).all().all()
    # Reports whose A + B gives the length
    both = reported["to_bow_m"].notna() & reported["to_stern_m"].notna()
    assert (
        reported.loc[both, "length_m"]
        == reported.loc[both, "to_bow_m"] + reported.loc[both, "to_stern_m"]
    ).all()
    positions = batch.positions.to_pandas()
    with_parts = positions.dropna(subset=PARTS, how="all")
    assert len(with_parts) > 1000
    # Each position's four are those of one static report of her (never mixed).
    sent = {
        (row.mmsi, *np.nan_to_num(np.array([getattr(row, p) for p in PARTS]), nan=-1))
        for row in reported.itertuples()
    }
    for row in with_parts.drop_duplicates(["mmsi", *PARTS]).itertuples():
        key = (row.mmsi, *np.nan_to_num(np.array([getattr(row, p) for p in PARTS]), nan=-1))
        assert key in sent


def _nmea(lines: list[str]) -> tuple[pd.DataFrame, pd.DataFrame, RejectsLedger]:
    ledger = RejectsLedger()
    (batch,) = read_nmea(lines, "log.nmea", ledger)
    return batch.positions.to_pandas(), batch.statics.to_pandas(), ledger


Fields = dict[str, str | int | float | bytes | bool]


def _static(seconds: int, mmsi: int = 219000001, **fields: int) -> list[str]:
    values: Fields = {"type": 5, "mmsi": mmsi, "ship_type": 70, "draught": 5.2}
    values.update(fields)
    sentences = encode_dict(values, radio_channel="A", seq_id=seconds % 10)
    return [f"{s},{NOON + seconds}" for s in sentences]


def _at(seconds: int, mmsi: int = 219000001) -> str:
    fields: Fields = {"type": 1, "mmsi": mmsi, "lat": 57.05, "lon": 9.92}
    (sentence,) = encode_dict(fields, radio_channel="A")
    return f"{sentence},{NOON + seconds}"


def test_nmea_reference_point_not_available_gives_the_length() -> None:
    """A = C = 0 with B, D > 0: the vessel is B long and D wide (no length before)."""
    dims = {"to_bow": 0, "to_stern": 90, "to_port": 0, "to_starboard": 14}
    positions, statics, ledger = _nmea([*_static(0, **dims), _at(5)])
    assert statics.loc[0, ["length_m", "breadth_m"]].tolist() == [90.0, 14.0]
    assert statics.loc[0, PARTS].isna().all()
    assert positions.loc[0, ["length_m", "breadth_m"]].tolist() == [90.0, 14.0]
    assert positions.loc[0, PARTS].isna().all()
    assert not ledger.dropped


def test_nmea_one_sided_zero_keeps_the_other_parts() -> None:
    dims = {"to_bow": 30, "to_stern": 10, "to_port": 0, "to_starboard": 6}
    positions, _, _ = _nmea([*_static(0, **dims), _at(5)])
    row = positions.loc[0]
    assert [row[p] for p in ("to_bow_m", "to_stern_m", "to_starboard_m")] == [30.0, 10.0, 6.0]
    assert np.isnan(row["to_port_m"]) and np.isnan(row["breadth_m"])
    assert row["length_m"] == 40.0


def test_nmea_the_four_come_from_one_report_never_mixed() -> None:
    """The report nearest in time with any part gives all four: here the later one, whose
    A is "not available"; the length still comes from the nearest report that has one."""
    first = {"to_bow": 10, "to_stern": 40, "to_port": 4, "to_starboard": 6}
    second = {"to_bow": 0, "to_stern": 45, "to_port": 5, "to_starboard": 5}
    positions, _, _ = _nmea([*_static(0, **first), *_static(60, **second), _at(55)])
    row = positions.loc[0]
    assert np.isnan(row["to_bow_m"])  # not the first report's 10
    assert [row["to_stern_m"], row["to_port_m"], row["to_starboard_m"]] == [45.0, 5.0, 5.0]
    assert row["length_m"] == 50.0 and row["breadth_m"] == 10.0


def test_nmea_implausible_row_counted_once_with_all_parts_null() -> None:
    dims = {"to_bow": 511, "to_stern": 511, "to_port": 63, "to_starboard": 63}
    positions, statics, ledger = _nmea([*_static(0, **dims), _at(5)])
    assert ledger.dropped == {"implausible_dimension": 1}  # length and breadth: one row
    assert statics.loc[0, ["length_m", "breadth_m", *PARTS]].isna().all()
    assert positions.loc[0, ["length_m", "breadth_m", *PARTS]].isna().all()


def _dma_rows(tmp_path: Path, rows: dict[str, dict[str, str]]) -> Path:
    """The DMA fixture with rows of some MMSIs changed (columns by name)."""
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    header = lines[0].lstrip("# ").split(",")
    out = [lines[0]]
    for line in lines[1:]:
        fields = line.split(",")
        for name, value in rows.get(fields[header.index("MMSI")], {}).items():
            fields[header.index(name)] = value
        out.append(",".join(fields))
    path = tmp_path / "changed.csv"
    path.write_text("\n".join(out) + "\n", encoding="utf-8")
    return path


def test_dma_reference_point_one_sided_and_implausible_rows(tmp_path: Path) -> None:
    path = _dma_rows(
        tmp_path,
        {
            # A = C = 0: 90 m by 14 m, whatever Length and Width say
            "257739000": {"A": "0", "B": "90", "C": "0", "D": "14", "Length": "", "Width": ""},
            # one-sided zero: the length from the Length column, B kept
            "371420000": {"A": "0", "B": "31", "C": "10", "D": "22", "Length": "229"},
            # A + B and C + D beyond what ships have: one row, counted once, all four null
            "259222000": {"A": "400", "B": "200", "C": "30", "D": "60"},
            # a lone A beyond the limits: counted, all four null, though Length is plausible
            "219004128": {"A": "600", "B": ""},
        },
    )
    data = load_ais([path])
    assert data.ledger.balanced
    assert data.ledger.dropped == {"implausible_dimension": 2}
    rows = data.positions.set_index("mmsi")
    assert rows.loc[257739000, ["length_m", "breadth_m"]].tolist() == [90.0, 14.0]
    assert rows.loc[257739000, PARTS].isna().all()
    assert rows.loc[371420000, ["length_m", "breadth_m"]].tolist() == [229.0, 32.0]
    assert np.isnan(rows.loc[371420000, "to_bow_m"])
    assert rows.loc[371420000, ["to_stern_m", "to_port_m", "to_starboard_m"]].tolist() == [
        31.0,
        10.0,
        22.0,
    ]
    for mmsi in (259222000, 219004128):
        assert rows.loc[mmsi, [*PARTS, "length_m"]].isna().all()


def test_mapped_reference_point_not_available(tmp_path: Path) -> None:
    source = (AIS_FIXTURES / "aishub_sample.csv").read_text(encoding="utf-8").splitlines()
    header = source[0].split(",")
    fields = source[2].split(",")  # 636021061: 146, 62, 15, 15
    for name, value in zip("ABCD", ("0", "208", "0", "30"), strict=True):
        fields[header.index(name)] = value
    path = tmp_path / "aishub.csv"
    path.write_text("\n".join([source[0], ",".join(fields), *source[3:]]) + "\n")
    data = load_ais([path], fmt=f"columns:{ROOT / 'examples' / 'column_maps' / 'aishub.toml'}")
    row = data.positions.set_index("mmsi").loc[636021061]
    assert [row["length_m"], row["breadth_m"]] == [208.0, 30.0]
    assert row[PARTS].isna().all()


# -- Parquet files and datasets ---------------------------------------------------------------


def _without_parts(table: pa.Table) -> pa.Table:
    return table.drop_columns(PARTS)


def test_a_parquet_file_without_the_parts_is_read_with_them_null(tmp_path: Path) -> None:
    want = load_ais([DMA26])
    table = pa.Table.from_pandas(want.positions, schema=CANONICAL_SCHEMA, preserve_index=False)
    pq.write_table(_without_parts(table), tmp_path / "old.parquet")
    pq.write_table(table, tmp_path / "new.parquet")
    old = load_ais([tmp_path / "old.parquet"]).positions
    new = load_ais([tmp_path / "new.parquet"]).positions
    assert old[PARTS].isna().all().all()
    pd.testing.assert_frame_equal(old.drop(columns=PARTS), want.positions.drop(columns=PARTS))
    pd.testing.assert_frame_equal(new, want.positions)


def test_a_parquet_file_is_cleaned_again(tmp_path: Path) -> None:
    """Another tool's canonical file: 0 is "not available", A = C = 0 is no reference point,
    and a row whose length is implausible has its parts dropped, counted once."""
    base = load_ais([DMA26]).positions.iloc[:3].reset_index(drop=True)
    base.loc[0, PARTS] = [0.0, 90.0, 0.0, 14.0]
    base.loc[1, PARTS] = [0.0, 31.0, 10.0, 22.0]
    base.loc[2, "length_m"] = 600.0
    table = pa.Table.from_pandas(base, schema=CANONICAL_SCHEMA, preserve_index=False)
    pq.write_table(table, tmp_path / "other.parquet")
    data = load_ais([tmp_path / "other.parquet"])
    assert data.ledger.dropped == {"implausible_dimension": 1}
    rows = data.positions.set_index("mmsi")
    assert rows.loc[base.loc[0, "mmsi"], PARTS].isna().all()
    assert np.isnan(rows.loc[base.loc[1, "mmsi"], "to_bow_m"])
    assert rows.loc[base.loc[1, "mmsi"], "to_stern_m"] == 31.0
    assert rows.loc[base.loc[2, "mmsi"], ["length_m", *PARTS]].isna().all()


def _as_version_1(dataset: Path) -> None:
    """Make ``dataset`` what colregs9 wrote before the schema had A, B, C, D: files without
    the four columns, a manifest of format version 1 without per-input versions."""
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    for entry in manifest["inputs"]:
        del entry["format_version"]
        for listed in entry["files"]:
            path = dataset / listed["path"]
            pq.write_table(_without_parts(pq.read_table(path)), path, compression="zstd")
    manifest["format_version"] = 1
    manifest["schema"] = manifest_schema(1)
    (dataset / MANIFEST_NAME).write_text(json.dumps(manifest))


@pytest.fixture(scope="module")
def version_1(tmp_path_factory: pytest.TempPathFactory) -> Path:
    dataset = tmp_path_factory.mktemp("v1") / "ais"
    ingest([DMA26], dataset)
    _as_version_1(dataset)
    return dataset


def test_a_version_1_dataset_is_read_with_the_parts_null(version_1: Path) -> None:
    want = load_ais([DMA26])
    got = load_ais([version_1])
    assert got.ledger.to_dict() == want.ledger.to_dict()
    assert got.positions[PARTS].isna().all().all()
    pd.testing.assert_frame_equal(
        got.positions.drop(columns=PARTS), want.positions.drop(columns=PARTS)
    )
    pd.testing.assert_frame_equal(got.dimension_reports, want.dimension_reports)


def test_ingest_into_a_version_1_dataset_upgrades_its_manifest(
    version_1: Path, tmp_path: Path
) -> None:
    dataset = tmp_path / "ais"
    shutil.copytree(version_1, dataset)
    ingest([DMA22, NMEA], dataset)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    assert manifest["format_version"] == 3 and manifest["schema"] == manifest_schema()
    assert [entry["format_version"] for entry in manifest["inputs"]] == [1, 3, 3]
    positions = load_ais([dataset]).positions
    from_nmea = positions["timestamp"].dt.year == 2013
    assert positions.loc[from_nmea, "to_bow_m"].notna().sum() > 1000  # the new input's
    from_dma26 = positions["timestamp"].dt.year == 2024
    assert from_dma26.any() and positions.loc[from_dma26, PARTS].isna().all().all()


def _damaged(version_1: Path, tmp_path: Path) -> Path:
    dataset = tmp_path / "ais"
    shutil.copytree(version_1, dataset)
    return dataset


def test_a_version_1_dataset_with_files_of_another_schema_is_refused(
    version_1: Path, tmp_path: Path
) -> None:
    dataset = _damaged(version_1, tmp_path)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    listed = dataset / manifest["inputs"][0]["files"][0]["path"]
    table = pq.read_table(listed)
    pq.write_table(table.append_column("to_bow_m", pa.nulls(table.num_rows, pa.float64())), listed)
    with pytest.raises(
        InputFileError,
        match=r"'to_bow_m', which the schema of format version 1 has not.*re-create the "
        r"dataset with colregs9 ingest",
    ):
        load_ais([dataset])


@pytest.mark.parametrize(
    ("version", "schema_version", "message"),
    [
        (2, 1, "not the canonical schema of format version 2; re-create the dataset"),
        (1, 2, "not the canonical schema of format version 1; re-create the dataset"),
        (4, 2, "format version 4, this colregs9 reads versions 1, 2, 3"),
    ],
)
def test_a_manifest_whose_version_and_schema_disagree_is_refused(
    version_1: Path, tmp_path: Path, version: int, schema_version: int, message: str
) -> None:
    dataset = _damaged(version_1, tmp_path)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    manifest["format_version"] = version
    manifest["schema"] = manifest_schema(schema_version)
    (dataset / MANIFEST_NAME).write_text(json.dumps(manifest))
    with pytest.raises(InputFileError, match=message):
        load_ais([dataset])


def test_a_version_2_input_must_say_its_version(tmp_path: Path) -> None:
    dataset = tmp_path / "ais"
    ingest([DMA26], dataset)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    del manifest["inputs"][0]["format_version"]
    (dataset / MANIFEST_NAME).write_text(json.dumps(manifest))
    with pytest.raises(InputFileError, match="input 1 of the manifest is malformed"):
        load_ais([dataset])


# -- a vessel's statics -----------------------------------------------------------------------


def _reports(*parts: tuple[float, float, float, float], start_s: int = 0) -> pd.DataFrame:
    return pd.DataFrame(
        {
            "mmsi": 219000001,
            "timestamp": pd.to_datetime(
                [start_s + 10 * i for i in range(len(parts))], unit="s", utc=True
            ),
            "length_m": 50.0,
            **{name: [p[i] for p in parts] for i, name in enumerate(ANTENNA_OFFSET_COLUMNS)},
        }
    )


def test_the_tracks_know_the_canonical_offsets() -> None:
    assert set(ANTENNA_OFFSET_COLUMNS) <= set(STATIC_COLUMNS) <= set(CANONICAL_COLUMNS)
    assert ANTENNA_OFFSET_COLUMNS == ANTENNA_OFFSETS


def test_latest_statics_take_the_four_from_one_report() -> None:
    positions = _reports((10, 40, 4, 6), (NAN, 45, 5, 5), (NAN, NAN, NAN, NAN))
    latest = latest_statics(positions).loc[219000001]
    # The last report with any part, its A "not available": not 10 from the first.
    assert np.isnan(latest["to_bow_m"])
    assert latest[["to_stern_m", "to_port_m", "to_starboard_m"]].tolist() == [45, 5, 5]
    assert latest["length_m"] == 50.0


def test_latest_statics_over_slabs_keep_the_four_together() -> None:
    earlier = latest_statics(_reports((10, 40, 4, 6)))
    later = latest_statics(_reports((NAN, 45, NAN, NAN), start_s=100), earlier).loc[219000001]
    assert np.isnan(later["to_bow_m"]) and np.isnan(later["to_port_m"])
    assert later["to_stern_m"] == 45
    none = latest_statics(_reports((NAN, NAN, NAN, NAN), start_s=100), earlier).loc[219000001]
    assert none[list(ANTENNA_OFFSET_COLUMNS)].tolist() == [10, 40, 4, 6]


# -- the hull distance ------------------------------------------------------------------------

NESTOR = VesselDimensions(90.0, 14.0, 5.0, (), "")
NESTOR_AIS = {"to_bow_m": 78.0, "to_stern_m": 12.0, "to_port_m": 7.0, "to_starboard_m": 7.0}


def test_hull_offsets_use_the_reported_antenna_position() -> None:
    assert hull_offsets(NESTOR, NESTOR_AIS) == HullOffsets(78.0, 12.0, 7.0, 7.0)
    centred = hull_offsets(NESTOR, {})
    assert centred == centred_offsets(90.0, 14.0) and centred.defaulted
    # A and B but no C, D: her A, B, centred across her breadth, marked assumed
    mixed = hull_offsets(NESTOR, {"to_bow_m": 78.0, "to_stern_m": 12.0})
    assert mixed == HullOffsets(78.0, 12.0, 7.0, 7.0, defaulted=True)
    defaulted = VesselDimensions(50.1, 9.2, 3.2, ("length_m", "breadth_m", "draught_m"), "*,*")
    assert not hull_offsets(defaulted, {}).known  # a table default draws no hull


def test_nestor_astern_of_a_small_vessel() -> None:
    """NESTOR (90 m, antenna 78 m from the bow) 150 m astern of a 10 m vessel, both heading
    north: her bow is 78 m ahead of her antenna, not 45 m, so the hulls are 150 - 78 - 5 =
    67 m apart, not 150 - 45 - 5 = 100 m."""
    lat, lon = 57.05, 9.92
    ahead_lat, ahead_lon = sail(lat, lon, 0.0, 150.0)
    window = pd.DataFrame(
        {
            "own_lat_deg": [lat],
            "own_lon_deg": [lon],
            "own_heading_deg": [0.0],
            "target_lat_deg": [float(ahead_lat)],
            "target_lon_deg": [float(ahead_lon)],
            "target_heading_deg": [0.0],
        }
    )
    small = centred_offsets(10.0, 4.0)
    ais = least_hull_separation_m(window, (hull_offsets(NESTOR, NESTOR_AIS), small))
    amidships = least_hull_separation_m(window, (hull_offsets(NESTOR, {}), small))
    assert ais == pytest.approx(67.0, abs=0.01)
    assert amidships == pytest.approx(100.0, abs=0.01)


def _greenhopper(tmp_path: Path, parts: dict[str, str] | None) -> tuple[float, bool]:
    """The demo's not-restricted scenario replayed, with the target's A, B, C, D replaced."""
    simulated = simulate_scenario(SCENARIOS / "greenhopper_not_restricted.toml", tmp_path / "a.csv")
    path = simulated.out_path
    if parts is not None:
        frame = pd.read_csv(path, dtype=str, keep_default_na=False)
        target = frame["MMSI"] == "219999002"
        for column, value in parts.items():
            frame.loc[target, column] = value
        frame.to_csv(path, index=False)
    result = run_replay([path], query_path=GREENHOPPER_QUERY, plots=False, write=False)
    (pair,) = result.pairs
    summary = pair.summary
    assert summary.actual_min_separation_hull_m is not None
    assert summary.hull_antenna_position_assumed is not None
    return summary.actual_min_separation_hull_m, summary.hull_antenna_position_assumed


def test_replay_places_the_hull_by_a_b_c_d(tmp_path: Path) -> None:
    """The simulator writes the antenna amidships (A = B): the distance is the centred one,
    not assumed. Without A-D it is the same distance, assumed. The target (50 m) with her
    antenna 45 m from the bow: another distance, not assumed."""
    written, written_assumed = _greenhopper(tmp_path, None)
    blank, blank_assumed = _greenhopper(tmp_path, {"A": "", "B": "", "C": "", "D": ""})
    aft, aft_assumed = _greenhopper(tmp_path, {"A": "45", "B": "5"})
    assert (written_assumed, blank_assumed, aft_assumed) == (False, True, False)
    assert written == pytest.approx(blank, abs=1e-6)
    assert abs(aft - written) > 1.0
    assert abs(aft - written) <= 20.0 + 1e-6  # her bow moved 20 m: no more than that
