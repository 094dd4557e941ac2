"""Every kind of bad input, through every command, as the user meets it.

Each case is a command line on a bad file, query, scenario, chart, option or output path. The
cases run through the real CLI (Typer in standalone mode) in one subprocess
(``cli_driver.py``, so that the suite stays fast); a handful also run as console scripts of
their own. For a refused input the test asserts the exit code, exactly one ``Error:`` line that
names the file, option or key, no traceback, and nothing else on stderr (a malformed command
line too: no usage block from Click). For an input accepted with rejects, the run succeeds and
its ledger balances.
"""

from __future__ import annotations

import atexit
import bz2
import gzip
import io
import json
import lzma
import os
import re
import shutil
import struct
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from colregs9_cli.ais.schema import CANONICAL_SCHEMA

from fixture_files import DEMO_DATA, DMA22, DMA26, MARINECADASTRE, MODELLED_CHART, NMEA, ROOT

ANNAPOLIS_ENC = ROOT / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"
DRIVER = Path(__file__).with_name("cli_driver.py")
SCENARIO = (DEMO_DATA / "greenhopper_restricted.toml").read_text(encoding="utf-8")


@dataclass(frozen=True)
class Case:
    """One command line; ``code`` 0 means accepted (with rejects in the ledger)."""

    id: str
    args: tuple[str, ...]
    code: int
    names: str = ""  # text the Error line must hold (the file, option or key)
    ledger: str | None = None  # accepted: where run.json lies, relative to the work dir
    extra: dict[str, str] = field(default_factory=dict)


def _dma_lines() -> list[str]:
    return DMA26.read_text(encoding="utf-8").splitlines()


def _write(work: Path, name: str, data: bytes | str) -> str:
    path = work / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        path.write_text(data, encoding="utf-8")
    else:
        path.write_bytes(data)
    return name


def _zip(members: dict[str, bytes], flag_bits: int = 0, method: int | None = None) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    data = bytearray(buffer.getvalue())
    if not flag_bits and method is None:
        return bytes(data)
    for signature, flags_at, method_at in ((b"PK\x03\x04", 6, 8), (b"PK\x01\x02", 8, 10)):
        at = data.index(signature)
        if flag_bits:
            struct.pack_into("<H", data, at + flags_at, flag_bits)
        if method is not None:
            struct.pack_into("<H", data, at + method_at, method)
    return bytes(data)


def _tar(name: str, data: bytes) -> bytes:
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w:gz") as archive:
        info = tarfile.TarInfo(name)
        info.size = len(data)
        archive.addfile(info, io.BytesIO(data))
    return buffer.getvalue()


def _parquet(table: pa.Table) -> bytes:
    buffer = io.BytesIO()
    pq.write_table(table, buffer)
    return buffer.getvalue()


def _ais_files(work: Path) -> dict[str, str]:
    """Bad AIS inputs: name -> file (relative to ``work``)."""
    lines = _dma_lines()
    dma = DMA26.read_bytes()
    header, rows = lines[0], lines[1:]
    files = {
        "missing": "no_such_file.csv",
        "directory": _write(work, "a_directory/keep", "") and "a_directory",
        "empty": _write(work, "empty.csv", b""),
        "header_only": _write(work, "header_only.csv", header + "\n"),
        "blank_lines": _write(work, "blank.csv", "\n\n\n"),
        "binary": _write(work, "binary.csv", bytes(range(256)) * 4),
        "unknown_layout": _write(work, "unknown.csv", "a,b,c\n1,2,3\n"),
        "headerless_dma": _write(work, "headerless.csv", "\n".join(rows) + "\n"),
        "headerless_iso": _write(
            work, "headerless_mc.csv", "\n".join(MARINECADASTRE.read_text().splitlines()[1:])
        ),
        "truncated_gzip": _write(work, "truncated.csv.gz", gzip.compress(dma)[:200]),
        "truncated_bz2": _write(work, "truncated.csv.bz2", bz2.compress(dma)[:200]),
        "truncated_xz": _write(work, "truncated.csv.xz", lzma.compress(dma)[:200]),
        "garbage_zstd": _write(work, "garbage.csv.zst", b"\x28\xb5\x2f\xfd" + b"\x00" * 50),
        "zip_two_csvs": _write(work, "two.zip", _zip({"a.csv": dma, "b.csv": dma})),
        "zip_empty": _write(work, "empty.zip", _zip({})),
        "zip_encrypted": _write(work, "encrypted.zip", _zip({"a.csv": dma}, flag_bits=0x1)),
        "zip_aes": _write(work, "aes.zip", _zip({"a.csv": dma}, method=99)),
        "zip_deflate64": _write(work, "deflate64.zip", _zip({"a.csv": dma}, method=9)),
        "zip_truncated": _write(work, "truncated.zip", _zip({"a.csv": dma})[:300]),
        "tar_gz": _write(work, "aisdk.tar.gz", _tar("aisdk.csv", dma)),
        "not_utf8": _write(work, "latin1.csv", dma.replace(b"ARCTIC", "ÅRCTIC".encode("latin-1"))),
        "parquet_missing_column": _write(
            work, "missing_column.parquet", _parquet(pa.table({"mmsi": [219000000]}))
        ),
        "parquet_duplicate_column": _write(
            work,
            "duplicate_column.parquet",
            _parquet(pa.Table.from_arrays([pa.array([1]), pa.array([2])], names=["mmsi", "mmsi"])),
        ),
        "parquet_gzipped": _write(
            work, "table.parquet.gz", gzip.compress(_parquet(pa.table({"mmsi": [1]})))
        ),
        "parquet_truncated": _write(
            work, "truncated.parquet", _parquet(pa.table({"mmsi": [1, 2, 3]}))[:30]
        ),
        "nmea_gps_only": _write(
            work,
            "gps_only.nmea",
            "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\n" * 5,
        ),
        "nmea_bad_checksums": _write(
            work, "bad_checksums.nmea", "!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*00\n" * 5
        ),
        "newline_name": _write(work, "new\nline.csv", "a\nb\n"),
        "all_rows_bad_mmsi": _write(
            work,
            "bad_mmsi.csv",
            "\n".join([header, *(r.replace(",Class A,", ",Class A,x") for r in rows)]),
        ),
    }
    return files


def _accepted_ais(work: Path) -> dict[str, str]:
    """Inputs with bad rows that are read: the rows go to the ledger."""
    lines = _dma_lines()
    header, rows = lines[0], lines[1:]
    long_line = rows[0] + "," + "x" * (8 * 1024 * 1024)
    return {
        "year_9999": _write(
            work,
            "year9999.csv",
            "\n".join([header, rows[0].replace("09/09/2024", "09/09/9999"), *rows[1:]]),
        ),
        "inf_dimension": _write(
            work,
            "inf.csv",
            "\n".join([header, *(r.replace(",49,288,", ",inf,1e400,") for r in rows)]),
        ),
        "mmsi_20_digits": _write(
            work,
            "mmsi20.csv",
            "\n".join([header, rows[0].replace("257739000", "1" * 20), *rows[1:]]),
        ),
        "line_8_mb": _write(work, "long_line.csv", "\n".join([header, long_line, *rows[1:]])),
        "wrong_field_count": _write(
            work, "fields.csv", "\n".join([header, rows[0] + ",extra", *rows[1:]])
        ),
        "text_latitude": _write(
            work,
            "text_lat.csv",
            "\n".join([header, rows[0].replace("54.672737", "north"), *rows[1:]]),
        ),
        "bad_time": _write(
            work,
            "bad_time.csv",
            "\n".join(
                [header, rows[0].replace("09/09/2024 00:00:33", "32/13/2024 99:00:00"), *rows[1:]]
            ),
        ),
    }


def _queries(work: Path) -> dict[str, tuple[str, str]]:
    """Bad query TOML: name -> (file, text the Error line must hold)."""
    texts = {
        "syntax": ("name = ", "TOML syntax error"),
        "unknown_key": ("colour = 1", "unknown key 'colour'"),
        "region_not_table": ("region = 5", "region must be a table"),
        "region_half": ("[region]\nlat_min = 1.0", "[region]"),
        "region_text": (
            '[region]\nlat_min = "a"\nlat_max = 2\nlon_min = 1\nlon_max = 2',
            "[region]",
        ),
        "region_inverted": (
            "[region]\nlat_min = 5\nlat_max = 2\nlon_min = 1\nlon_max = 2",
            "lat_min",
        ),
        "polygon_not_json": ("[region]\npolygon = '{nope'", "not valid JSON"),
        "polygon_point": ('[region]\npolygon = \'{"type":"Point","coordinates":[1,2]}\'', "Point"),
        "polygon_nan": (
            '[region]\npolygon = \'{"type":"Polygon","coordinates":[[[1,2],[3,NaN],[1,2]]]}\'',
            "not a finite number",
        ),
        "polygon_features": (
            '[region]\npolygon = \'{"type":"FeatureCollection","features":5}\'',
            "features",
        ),
        "polygon_deep": (
            "[region]\npolygon = '" + "[" * 5000 + "]" * 5000 + "'",
            "nested too deeply",
        ),
        "polygon_file_missing": ("[region]\npolygon_file = 'none.geojson'", "none.geojson"),
        "polygon_self_intersecting": (
            "[region]\npolygon = '"
            + json.dumps(
                {"type": "Polygon", "coordinates": [[[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]]]}
            )
            + "'",
            "not valid",
        ),
        "time_not_time": ("[time]\nstart = 5", "[time] start"),
        "time_text": ('[time]\nstart = "yesterday"', "[time] start"),
        "time_inverted": (
            "[time]\nstart = 2024-09-10T00:00:00Z\nend = 2024-09-09T00:00:00Z",
            "not before",
        ),
        "time_year_9999": ("[time]\nstart = 9999-12-31T23:59:59-05:00", "[time] start"),
        "name_path": ('name = "../../x"', "name"),
        "name_nul": ('name = "a\\u0000b"', "name"),
        "mmsi_text": ('[vessels]\nmmsi_include = "abc"', "mmsi_include"),
        "mmsi_nested": ("[vessels]\nmmsi_include = [[1, 2]]", "mmsi_include"),
        "mmsi_mixed": ('[vessels]\nmmsi_include = [219000000, "x"]', "mmsi_include"),
        "mobile_type_bad": ('[vessels]\nmobile_types = ["Class Z"]', "mobile_types"),
        "length_negative": ("[vessels]\nlength_min_m = -5", "length_min_m"),
        "replay_not_table": ("replay = [1, 2]", "replay"),
        "replay_step_text": ('[replay]\nstep_s = "x"', "step_s"),
        "replay_step_negative": ("[replay]\nstep_s = -1", "step_s"),
        "replay_step_memory": ("[replay]\nstep_s = 1e-6", "step_s"),
        "replay_gap_below_step": ("[replay]\nstep_s = 400", "max_gap_s"),
        "replay_statuses_nested": (
            "[replay]\nrestricted_nav_statuses = [[3]]",
            "restricted_nav_statuses",
        ),
        "replay_statuses_range": (
            "[replay]\nrestricted_nav_statuses = [99]",
            "restricted_nav_statuses",
        ),
        "replay_unknown": ("[replay]\nfoo = 1", "unknown key 'foo'"),
        "colregs_unknown": ("[colregs]\nhead_on_deg = 6", "head_on_deg"),
        "colregs_sectors": ("[colregs]\novertaking_sector_min_deg = 300", "overtaking_sector"),
        "colregs_course_source": ('[colregs]\ncourse_source = "gyro"', "course_source"),
        "alpha_range": ("[manoeuvrability]\nalpha = 5", "alpha"),
        "alpha_text": ('[manoeuvrability]\nalpha = "z"', "alpha"),
        "ingest_time_sources": ('[ingest]\nnmea_time_sources = ["sundial"]', "nmea_time_sources"),
        "ingest_time_sources_nested": (
            '[ingest]\nnmea_time_sources = [["pghp"]]',
            "[ingest]: key 'nmea_time_sources'",
        ),
        "ingest_time_sources_table": ("[ingest]\nnmea_time_sources = {x = 1}", "nmea_time_sources"),
        "manoeuvrability_swing_model_list": (
            "[manoeuvrability]\nswing_model = []",
            "[manoeuvrability]: key 'swing_model'",
        ),
        "manoeuvrability_policy_nested": ("[manoeuvrability]\npolicy = [[1]]", "'policy'"),
        "manoeuvrability_step_memory": ("[manoeuvrability]\nstep_s = 1e-6", "step_s"),
        "manoeuvrability_horizon_huge": ("[manoeuvrability]\nhorizon_s = 1e12", "horizon_s"),
        "colregs_course_source_table": ("[colregs]\ncourse_source = {x = 1}", "course_source"),
        "replay_slab_tiny": ("[replay]\nslab_s = 1e-300", "slab_s"),
        "replay_slab_huge": ("[replay]\nslab_s = 1e300", "slab_s"),
        "replay_range_tiny": ("[replay]\ncandidate_range_m = 1e-300", "candidate_range_m"),
        "replay_range_below_cpa": ("[replay]\ncandidate_range_m = 100", "candidate_range_m"),
        "polygon_empty": (
            '[region]\npolygon = \'{"type":"Polygon","coordinates":[]}\'',
            "[region] polygon",
        ),
        "polygon_file_directory": ("[region]\npolygon_file = '.'", "a directory, not a file"),
    }
    return {
        name: (_write(work, f"queries/{name}.toml", text + "\n"), expected)
        for name, (text, expected) in texts.items()
    }


def _scenarios(work: Path) -> dict[str, tuple[str, str]]:
    chart = str(MODELLED_CHART)
    base = SCENARIO.replace('chart = "aalborg_modelled.geojson"', f"chart = {json.dumps(chart)}")
    edits = {
        "syntax": (base + "\n[[vessel]\n", "TOML syntax error"),
        "duration_huge": (base.replace("duration_s = 420.0", "duration_s = 1e13"), "duration_s"),
        "interval_tiny": (
            base.replace("ais_interval_s = 2.0", "ais_interval_s = 1e-12"),
            "ais_interval_s",
        ),
        "interval_not_multiple": (
            base.replace("ais_interval_s = 2.0", "ais_interval_s = 2.5"),
            "ais_interval_s",
        ),
        "name_path": (base.replace('name = "greenhopper_restricted"', 'name = "../../x"'), "name"),
        "duration_negative": (base.replace("duration_s = 420.0", "duration_s = -1"), "duration_s"),
        "duplicate_mmsi": (base.replace("mmsi = 219999002", "mmsi = 219999001"), "219999001"),
        "two_own": (base.replace('role = "target"', 'role = "own"', 1), "role"),
        "chart_missing": (
            base.replace(json.dumps(chart), '"no_chart.geojson"'),
            "no_chart.geojson",
        ),
        "unknown_key": (base + "\ncolour = 1\n", "colour"),
        "start_year_9999": (
            base.replace("start_utc = 2024-09-09T12:00:00Z", "start_utc = 9999-12-31T23:59:00Z"),
            "start_utc",
        ),
        "start_overflows": (
            base.replace(
                "start_utc = 2024-09-09T12:00:00Z", "start_utc = 9999-12-31T23:59:00-05:00"
            ),
            "start_utc",
        ),
        "start_1970": (
            base.replace("start_utc = 2024-09-09T12:00:00Z", "start_utc = 1970-01-01T00:00:00Z"),
            "start_utc",
        ),
        "chart_directory": (base.replace(json.dumps(chart), '"."'), "not a file"),
        "length_600": (base.replace("length_m = 50.0", "length_m = 600.0"), "length_m"),
        "draught_inf": (base.replace("draught_m = 0.5", "draught_m = inf"), "draught_m"),
        "speed_huge": (base.replace("speed_kn = 7.0", "speed_kn = 1e9"), "speed_kn"),
    }
    return {
        name: (_write(work, f"scenarios/{name}.toml", text), expected)
        for name, (text, expected) in edits.items()
    }


def _charts(work: Path) -> dict[str, str]:
    off_earth = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {"OBJL": "DEPARE", "DRVAL1": 5.0},
                "geometry": {
                    "type": "Polygon",
                    "coordinates": [[[500, 100], [501, 100], [501, 101], [500, 100]]],
                },
            }
        ],
    }
    no_drval = json.loads(MODELLED_CHART.read_text())
    for feature in no_drval["features"]:
        feature["properties"].pop("DRVAL1", None)
    nan_vertex = json.dumps(off_earth).replace(
        "[[500, 100], [501, 100], [501, 101], [500, 100]]",
        "[[10, 57], [NaN, 57], [10.1, 57.1], [10, 57]]",
    )
    return {
        "nan_vertex": _write(work, "charts/nan_vertex.geojson", nan_vertex),
        "zeroed_gpkg": _write(work, "charts/zeroed.gpkg", b"SQLite format 3\x00" + bytes(100)),
        "not_a_chart": _write(work, "charts/not_a_chart.geojson", "{nope"),
        "chart_text": _write(work, "charts/chart.000", "not an S-57 cell"),
        "off_earth": _write(work, "charts/off_earth.geojson", json.dumps(off_earth)),
        "no_drval1": _write(work, "charts/no_drval1.geojson", json.dumps(no_drval)),
    }


def _datasets(work: Path) -> dict[str, str]:
    """Datasets made by ``ingest`` (in-process), then spoilt: a foreign Parquet file beside
    the partitions, and a partition rewritten with another schema."""
    from colregs9_cli.jobs.ingest import ingest

    made = work / "datasets" / "good"
    foreign = work / "datasets" / "foreign"
    wrong = work / "datasets" / "wrong_schema"
    if not made.exists():  # the cases are listed twice (test_there_are_at_least_150_kinds)
        ingest([DMA26], made)
        shutil.copytree(made, foreign)
        pq.write_table(pa.table({"x": [1]}), foreign / "foreign.parquet")
        shutil.copytree(made, wrong)
        pq.write_table(pa.table({"mmsi": ["x"]}), next(wrong.rglob("*.parquet")))
    partition = next(wrong.rglob("*.parquet"))
    return {
        "good": "datasets/good",
        "foreign": "datasets/foreign",
        "wrong_schema": str(partition.relative_to(work)),
        "wrong_schema_dir": "datasets/wrong_schema",
    }


def _ingest_cases(
    work: Path, ais: dict[str, str], datasets: dict[str, str], a_file: str, good: str
) -> list[Case]:
    cases = []
    common = (
        "missing",
        "directory",
        "empty",
        "header_only",
        "binary",
        "unknown_layout",
        "headerless_dma",
        "truncated_gzip",
        "zip_two_csvs",
        "zip_encrypted",
        "tar_gz",
        "not_utf8",
        "parquet_missing_column",
        "parquet_duplicate_column",
        "nmea_gps_only",
        "nmea_bad_checksums",
        "all_rows_bad_mmsi",
    )
    for name in common:
        cases.append(
            Case(
                f"ingest-ais-{name}",
                ("ingest", ais[name], "--out", f"out/ingest-{name}", "--quiet"),
                2,
                ais[name],
            )
        )
    zero = _write(work, "zero_rows.parquet", _parquet(CANONICAL_SCHEMA.empty_table()))
    cases += [
        Case(
            "ingest-zero-rows-parquet",
            ("ingest", zero, "--out", "out/ingest-zero", "--quiet"),
            2,
            zero,
        ),
        Case("ingest-out-is-a-file", ("ingest", good, "--out", a_file, "--quiet"), 2, a_file),
        Case(
            "ingest-out-under-a-file",
            ("ingest", good, "--out", f"{a_file}/ds", "--quiet"),
            2,
            a_file,
        ),
        Case(
            "ingest-out-not-a-dataset",
            ("ingest", good, "--out", "foreign", "--quiet"),
            2,
            "not a colregs9 dataset",
        ),
        # A dataset --out is checked as stats and replay check it, before any input is read:
        # for an input already in it, and for a new one.
        Case(
            "ingest-into-dataset-foreign-parquet",
            ("ingest", good, "--out", datasets["foreign"], "--quiet"),
            2,
            "foreign.parquet",
        ),
        Case(
            "ingest-new-input-into-dataset-foreign-parquet",
            ("ingest", str(DMA22), "--out", datasets["foreign"], "--quiet"),
            2,
            "foreign.parquet",
        ),
        Case(
            "ingest-into-dataset-wrong-schema",
            ("ingest", str(DMA22), "--out", datasets["wrong_schema_dir"], "--quiet"),
            2,
            datasets["wrong_schema"],
        ),
        Case(
            "ingest-a-dataset-as-input",
            ("ingest", datasets["good"], "--out", "out/ingest-ds", "--quiet"),
            2,
            datasets["good"],
        ),
        Case(
            "ingest-query-bad",
            ("ingest", good, "--query", "queries/syntax.toml", "--out", "out/i-q", "--quiet"),
            2,
            "TOML syntax error",
        ),
        Case(
            "ingest-query-time-sources-nested",
            (
                "ingest",
                good,
                "--query",
                "queries/ingest_time_sources_nested.toml",
                "--out",
                "out/i-q2",
                "--quiet",
            ),
            2,
            "nmea_time_sources",
        ),
        Case(
            "ingest-format-bad",
            ("ingest", good, "--format", "csv", "--out", "out/i-f", "--quiet"),
            2,
            "--format",
        ),
    ]
    return cases


def _cases(work: Path) -> list[Case]:
    ais = _ais_files(work)
    accepted = _accepted_ais(work)
    datasets = _datasets(work)
    for fifo in ("a_fifo", "a_fifo.png"):  # never a device node: refused unopened
        if not (work / fifo).exists():
            os.mkfifo(work / fifo)
    (work / "plot_dir.png").mkdir(exist_ok=True)
    queries = _queries(work)
    scenarios = _scenarios(work)
    charts = _charts(work)
    a_file = _write(work, "a_file.txt", "x")
    one_vessel = _write(work, "one_vessel.csv", "\n".join(_dma_lines()[:2]) + "\n")
    _write(work, "foreign/notes.txt", "not a report")
    good = str(DMA26)
    cases: list[Case] = []
    exit_codes = {"nmea_gps_only": 2, "nmea_bad_checksums": 2, "all_rows_bad_mmsi": 2}
    for command in ("stats", "replay"):
        out = ("--out", f"out/{command}", "--quiet")
        for name, path in ais.items():
            expected = "new\\nline.csv" if name == "newline_name" else path
            cases.append(
                Case(
                    f"{command}-ais-{name}",
                    (command, path, *out),
                    exit_codes.get(name, 2),
                    expected,
                )
            )
        for name, path in accepted.items():
            target = f"ok/{command}-{name}"
            extra = ("--no-plots",) if command == "replay" else ()
            cases.append(
                Case(
                    f"{command}-accepted-{name}",
                    (command, path, "--out", target, "--quiet", *extra),
                    0,
                    ledger=f"{target}/run.json",
                )
            )
        for name, (path, expected) in queries.items():
            stages = ("replay", "colregs", "alpha", "manoeuvrability")
            if command == "stats" and name.split("_")[0] in stages:
                continue  # stats does not read the replay's tables
            cases.append(
                Case(f"{command}-query-{name}", (command, good, "--query", path, *out), 2, expected)
            )
        cases += [
            Case(
                f"{command}-out-is-a-file", (command, good, "--out", a_file, "--quiet"), 2, a_file
            ),
            Case(
                f"{command}-out-under-a-file",
                (command, good, "--out", f"{a_file}/x", "--quiet"),
                2,
                a_file,
            ),
            Case(
                f"{command}-out-foreign",
                (command, good, "--out", "foreign", "--quiet"),
                2,
                "foreign",
            ),
            Case(f"{command}-format-bad", (command, good, "--format", "csv", *out), 2, "--format"),
            Case(
                f"{command}-format-wrong",
                (command, good, "--format", "marinecadastre", *out),
                2,
                "basedatetime",
            ),
            Case(
                f"{command}-no-input",
                (command, "--quiet"),
                2,
                f"Missing argument 'AIS'. (see 'colregs9 {command} --help')",
            ),
            Case(
                f"{command}-query-a-directory",
                (command, good, "--query", "queries", *out),
                2,
                "queries: a directory, not a file",
            ),
            Case(
                f"{command}-dataset-foreign-parquet",
                (command, datasets["foreign"], *out),
                2,
                "foreign.parquet",
            ),
            Case(
                f"{command}-dataset-wrong-schema",
                (command, datasets["wrong_schema"], *out),
                2,
                datasets["wrong_schema"],
            ),
            Case(f"{command}-unknown-option", (command, good, "--bogus"), 2, "--bogus"),
        ]
    nmea = str(NMEA)
    replay_out = ("--out", "out/replay", "--quiet", "--no-plots")
    fifo = str(work / "a_fifo")
    cases += _ingest_cases(work, ais, datasets, a_file, good)
    cases += [
        Case(
            "replay-slab-tiny",
            ("replay", nmea, "--slab-minutes", "1e-9", *replay_out),
            2,
            "--slab-minutes",
        ),
        Case(
            "replay-slab-underflow",
            ("replay", nmea, "--slab-minutes", "1e-300", *replay_out),
            2,
            "slab_s",
        ),
        Case(
            "replay-slab-huge",
            ("replay", nmea, "--slab-minutes", "1e300", *replay_out),
            2,
            "slab_s",
        ),
        Case(
            "replay-range-tiny",
            ("replay", nmea, "--candidate-range-m", "1e-300", *replay_out),
            2,
            "candidate_range_m",
        ),
        Case(
            "replay-chart-nan-vertex",
            ("replay", nmea, "--chart", charts["nan_vertex"], *replay_out),
            2,
            f"{charts['nan_vertex']}: layer nan_vertex, feature 1 (DEPARE)",
        ),
        Case(
            "replay-chart-a-directory",
            ("replay", nmea, "--chart", "charts", *replay_out),
            2,
            "charts",
        ),
        Case(
            "chart-nan-vertex",
            ("chart", charts["nan_vertex"]),
            2,
            f"{charts['nan_vertex']}: layer nan_vertex, feature 1 (DEPARE)",
        ),
        Case("chart-zeroed-gpkg", ("chart", charts["zeroed_gpkg"]), 2, charts["zeroed_gpkg"]),
        Case(
            "chart-draught-huge",
            ("chart", str(MODELLED_CHART), "--draught", "1e308"),
            2,
            "--draught",
        ),
        Case(
            "chart-draught-nan", ("chart", str(MODELLED_CHART), "--draught", "nan"), 2, "--draught"
        ),
        Case(
            "chart-ukc-huge",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--ukc", "1e308"),
            2,
            "--ukc",
        ),
        Case(
            "stats-ais-a-fifo",
            ("stats", fifo, "--out", "out/stats", "--quiet"),
            2,
            f"{fifo}: a pipe or a device, not a file",
        ),
        Case(
            "chart-out-a-fifo",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", f"{fifo}.png"),
            2,
            "named pipe",
        ),
        Case(
            "chart-out-a-directory",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", "plot_dir.png"),
            2,
            "plot_dir.png: --out is a directory",
        ),
        # Path() would drop the trailing separator and write trail.png.
        Case(
            "chart-out-trailing-slash",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", "trail.png/"),
            2,
            "trail.png/: --out ends in a path separator",
        ),
        Case(
            "chart-out-gpkg-trailing-slash",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", "out/chart.gpkg/"),
            2,
            "out/chart.gpkg/: --out ends in a path separator",
        ),
        Case(
            "simulate-out-trailing-slash",
            (
                "simulate",
                str(DEMO_DATA / "greenhopper_restricted.toml"),
                "--out",
                "sim.csv/",
                "--quiet",
            ),
            2,
            "sim.csv/: --out ends in a path separator",
        ),
        Case(
            "simulate-out-a-fifo",
            ("simulate", str(DEMO_DATA / "greenhopper_restricted.toml"), "--out", fifo),
            2,
            "named pipe",
        ),
        Case("simulate-a-directory", ("simulate", "charts", "--quiet"), 2, "a directory"),
    ]
    cases += [
        Case(
            "stats-per-bad",
            ("stats", good, "--per", "ship", "--out", "out/s", "--quiet"),
            2,
            "--per",
        ),
        Case(
            "stats-by-bad",
            ("stats", good, "--by", "colour", "--out", "out/s", "--quiet"),
            2,
            "--by",
        ),
        Case("replay-step-negative", ("replay", nmea, "--step-s", "-1", *replay_out), 2, "step_s"),
        Case("replay-step-memory", ("replay", nmea, "--step-s", "1e-6", *replay_out), 2, "step_s"),
        Case(
            "replay-tcpa-nan", ("replay", nmea, "--tcpa-act-s", "nan", *replay_out), 2, "tcpa_act_s"
        ),
        Case(
            "replay-cpa-negative",
            ("replay", nmea, "--cpa-req-m", "-1", *replay_out),
            2,
            "cpa_req_m",
        ),
        Case(
            "replay-range-zero",
            ("replay", nmea, "--candidate-range-m", "0", *replay_out),
            2,
            "candidate_range_m",
        ),
        Case(
            "replay-min-sog-negative",
            ("replay", nmea, "--min-sog-kn", "-1", *replay_out),
            2,
            "min_sog_kn",
        ),
        Case("replay-alpha-range", ("replay", nmea, "--alpha", "2", *replay_out), 2, "alpha"),
        Case(
            "replay-slab-zero",
            ("replay", nmea, "--slab-minutes", "0", *replay_out),
            2,
            "--slab-minutes 0",
        ),
        Case(
            "replay-workers-zero", ("replay", nmea, "--workers", "0", *replay_out), 2, "--workers"
        ),
        Case(
            "replay-workers-text", ("replay", nmea, "--workers", "two", *replay_out), 2, "--workers"
        ),
        Case(
            "replay-scratch-missing",
            ("replay", nmea, "--scratch", "no_dir", *replay_out),
            2,
            "--scratch",
        ),
        Case(
            "replay-own-absent",
            ("replay", nmea, "--own-mmsi", "219999999", *replay_out),
            3,
            "219999999",
        ),
        Case(
            "replay-own-text", ("replay", nmea, "--own-mmsi", "abc", *replay_out), 2, "--own-mmsi"
        ),
        Case("replay-one-vessel", ("replay", one_vessel, *replay_out), 3, "1 vessel"),
        Case(
            "replay-chart-missing",
            ("replay", nmea, "--chart", "no_chart.000", *replay_out),
            2,
            "no_chart.000",
        ),
        Case(
            "replay-chart-not-a-chart",
            ("replay", nmea, "--chart", charts["not_a_chart"], *replay_out),
            2,
            charts["not_a_chart"],
        ),
        Case(
            "replay-chart-elsewhere",
            ("replay", nmea, "--chart", str(ANNAPOLIS_ENC), *replay_out),
            2,
            "does not cover",
        ),
        Case(
            "replay-chart-off-earth",
            ("replay", nmea, "--chart", charts["off_earth"], *replay_out),
            2,
            charts["off_earth"],
        ),
        Case(
            "replay-chart-no-drval1",
            ("replay", nmea, "--chart", charts["no_drval1"], *replay_out),
            2,
            "DRVAL1",
        ),
    ]
    for name, (path, expected) in scenarios.items():
        cases.append(
            Case(
                f"simulate-{name}",
                ("simulate", path, "--out", f"out/sim-{name}.csv", "--quiet"),
                2,
                expected,
            )
        )
    scenario = str(DEMO_DATA / "greenhopper_restricted.toml")
    cases += [
        Case("simulate-missing", ("simulate", "none.toml", "--quiet"), 2, "none.toml"),
        Case(
            "simulate-out-under-a-file",
            ("simulate", scenario, "--out", f"{a_file}/x.csv", "--quiet"),
            2,
            a_file,
        ),
        Case(
            "simulate-out-is-a-directory",
            ("simulate", scenario, "--out", "foreign", "--quiet"),
            2,
            "foreign",
        ),
        Case("chart-missing", ("chart", "none.000"), 2, "none.000"),
        Case("chart-not-a-chart", ("chart", charts["not_a_chart"]), 2, charts["not_a_chart"]),
        Case("chart-text-cell", ("chart", charts["chart_text"]), 2, charts["chart_text"]),
        Case("chart-off-earth", ("chart", charts["off_earth"]), 2, charts["off_earth"]),
        Case("chart-no-drval1", ("chart", charts["no_drval1"]), 2, "DRVAL1"),
        Case(
            "chart-draught-negative",
            ("chart", str(MODELLED_CHART), "--draught", "-1"),
            2,
            "draught",
        ),
        Case(
            "chart-ukc-negative",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--ukc", "-1"),
            2,
            "ukc",
        ),
        Case(
            "chart-out-suffix",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", "x.txt"),
            2,
            "x.txt",
        ),
        Case(
            "chart-out-no-draught", ("chart", str(MODELLED_CHART), "--out", "x.png"), 2, "--draught"
        ),
        Case(
            "chart-out-under-a-file",
            ("chart", str(MODELLED_CHART), "--draught", "2", "--out", f"{a_file}/x.png"),
            2,
            a_file,
        ),
        Case("swing-out-is-a-file", ("swing", "--out", a_file), 2, a_file),
        Case("swing-out-under-a-file", ("swing", "--out", f"{a_file}/x"), 2, a_file),
        Case("demo-out-is-a-file", ("demo", "--out", a_file, "--quiet"), 2, a_file),
        Case(
            "demo-scenarios-missing",
            ("demo", "--scenarios", "no_dir", "--out", "out/demo", "--quiet"),
            2,
            "no_dir",
        ),
        Case(
            "demo-chart-missing",
            ("demo", "--chart", "no_chart.geojson", "--out", "out/demo2", "--quiet"),
            2,
            "no_chart.geojson",
        ),
        Case(
            "demo-query-bad",
            ("demo", "--query", queries["syntax"][0], "--out", "out/demo3", "--quiet"),
            2,
            "TOML syntax error",
        ),
        Case("unknown-command", ("colour",), 2, "colour"),
        Case("unknown-global-option", ("--colour",), 2, "--colour"),
    ]
    # Click's own errors: one line naming the option and where the help is.
    for command in ("replay", "simulate", "stats", "ingest", "swing", "chart", "demo"):
        cases += [
            Case(f"{command}-unknown-option-alone", (command, "--bogus"), 2, "--bogus"),
            Case(
                f"{command}-option-without-value",
                (command, "--out"),
                2,
                "Option '--out' requires an argument",
            ),
        ]
    cases += [
        Case(
            "replay-option-not-a-number",
            ("replay", good, "--tcpa-act-s", "soon"),
            2,
            "Invalid value for '--tcpa-act-s'",
        ),
    ]
    return cases


# The cases' files are written once, when the module is collected (the ids need the cases),
# into a directory of their own that is removed at exit.
WORK = Path(tempfile.mkdtemp(prefix="colregs9-bad-inputs-"))
atexit.register(shutil.rmtree, WORK, ignore_errors=True)
CASES = {c.id: c for c in _cases(WORK)}
CASE_IDS = list(CASES)


@pytest.fixture(scope="module")
def work() -> Path:
    return WORK


@pytest.fixture(scope="module")
def cases() -> dict[str, Case]:
    return CASES


@pytest.fixture(scope="module")
def results(work: Path, cases: dict[str, Case]) -> dict[str, dict[str, object]]:
    listed = work / "cases.json"
    listed.write_text(
        json.dumps([{"id": c.id, "args": list(c.args), "cwd": str(work)} for c in cases.values()])
    )
    answers = work / "results.json"
    subprocess.run(
        [sys.executable, str(DRIVER), str(listed), str(answers)], check=True, timeout=600
    )
    return json.loads(answers.read_text())


def _check(case: Case, code: object, stdout: str, stderr: str, escaped: object, work: Path) -> None:
    assert escaped is None, f"an exception escaped:\n{escaped}"
    assert "Traceback" not in stderr + stdout
    assert "Warning" not in stderr, stderr
    assert code == case.code, f"exit {code}, expected {case.code}\n{stdout}{stderr}"
    errors = [line for line in stderr.splitlines() if line.startswith("Error:")]
    if case.code == 0:
        assert errors == []
        if case.ledger is not None:
            manifest = json.loads((work / case.ledger).read_text())
            ledger = manifest["ledger"]
            assert sum(ledger["rejects_by_reason"].values()) == ledger["rows_rejected"] > 0
            assert ledger["rows_read"] == (
                ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
            )
        return
    assert len(errors) == 1, stderr
    others = [
        line for line in stderr.splitlines() if line.strip() and not line.startswith("Error:")
    ]
    assert others == [], stderr
    assert case.names in errors[0], errors[0]


@pytest.mark.parametrize("case_id", CASE_IDS)
def test_bad_input(case_id: str, cases, results, work: Path) -> None:
    case = cases[case_id]
    result = results[case_id]
    _check(case, result["code"], result["stdout"], result["stderr"], result["escaped"], work)


def test_there_are_at_least_150_kinds() -> None:
    assert len(_cases(WORK)) == len(CASES) >= 150  # and no id twice


@pytest.mark.parametrize(
    "case_id",
    [
        "stats-ais-binary",
        "replay-query-polygon_deep",
        "simulate-duration_huge",
        "chart-off-earth",
        "replay-workers-text",
    ],
)
def test_as_a_console_script_of_its_own(case_id: str, cases, work: Path) -> None:
    """The same, in a process of its own, through ``python -m colregs9_cli``."""
    case = cases[case_id]
    done = subprocess.run(
        [sys.executable, "-m", "colregs9_cli", *case.args],
        capture_output=True,
        text=True,
        cwd=work,
        timeout=120,
        check=False,
    )
    _check(case, done.returncode, done.stdout, done.stderr, None, work)


# Issue 31 §2: inputs that gave a traceback (an AIS path that is a symbolic link that loops, a
# Parquet column twice, TOML nested thousands deep) and their siblings. Each refusal's whole
# Error line is checked; ``names`` holds it, after "Error: ".
LOOP = "Too many levels of symbolic links"
NAME_MAX = 255  # bytes in one path component, on the file systems pytest runs on


def _link(work: Path, name: str, target: str) -> str:
    path = work / name
    path.parent.mkdir(parents=True, exist_ok=True)
    if not os.path.lexists(path):
        path.symlink_to(target)
    return name


def _fifo(work: Path, name: str) -> str:
    if not os.path.lexists(work / name):
        os.mkfifo(work / name)
    return name


def _spoilt_dataset(work: Path, name: str) -> Path:
    """A copy of the dataset ``ingest`` made for the cases above, to spoil."""
    copy = work / "datasets" / name
    if not copy.exists():
        shutil.copytree(work / "datasets" / "good", copy)
    return copy


def _loop_cases(work: Path) -> list[Case]:
    loop = _link(work, "loop.csv", "loop.csv")
    through = _link(work, "loops/a", "b")
    _link(work, "loops/b", "a")
    out = _link(work, "out_loop", "out_loop")
    query = _link(work, "queries/loop.toml", "loop.toml")
    polygon = _write(work, "queries/polygon_loop.toml", "[region]\npolygon_file = 'loop.toml'\n")
    parent = _spoilt_dataset(work, "link_to_parent")
    _link(work, str((parent / "up").relative_to(work)), "..")
    broken = _spoilt_dataset(work, "broken_link")
    stray = _link(work, str((broken / "stray.parquet").relative_to(work)), "nowhere.parquet")
    cannot_open = f"cannot open it ({LOOP}); check the path and its symbolic links"
    scenario_text = (DEMO_DATA / "greenhopper_restricted.toml").read_text(encoding="utf-8")
    _link(work, "scenarios/chart_loop.geojson", "chart_loop.geojson")
    looping_chart = _write(
        work,
        "scenarios/chart_loop.toml",
        re.sub(r"(?m)^chart = .*$", 'chart = "chart_loop.geojson"', scenario_text),
    )
    cases = [
        Case(
            f"issue31-{command}-ais-symlink-loop",
            (command, loop, "--out", f"out/i31-{command}-loop", "--quiet"),
            2,
            f"{loop}: {cannot_open}",
        )
        for command in ("stats", "replay", "ingest")
    ]
    return [
        *cases,
        Case(
            "issue31-simulate-scenario-chart-symlink-loop",
            ("simulate", looping_chart, "--out", "out/i31-scenario.csv", "--quiet"),
            2,
            f"{looping_chart}: chart = 'chart_loop.geojson': {LOOP}; give the path of a chart file",
        ),
        Case(
            "issue31-stats-ais-loop-through-a-directory",
            ("stats", through, "--out", "out/i31-through", "--quiet"),
            2,
            f"{through}: {cannot_open}",
        ),
        Case(
            "issue31-stats-out-symlink-loop",
            ("stats", str(DMA26), "--out", out, "--quiet"),
            2,
            f"{out}: --out cannot be reached ({LOOP}); check the path and its symbolic links, "
            "or give another directory",
        ),
        Case(
            "issue31-stats-out-under-a-symlink-loop",
            ("stats", str(DMA26), "--out", f"{out}/report", "--quiet"),
            2,
            f"{out}/report: --out cannot be reached ({LOOP}); check the path and its symbolic "
            "links, or give another directory",
        ),
        Case(
            "issue31-stats-query-symlink-loop",
            ("stats", str(DMA26), "--query", query, "--out", "out/i31-q-loop", "--quiet"),
            2,
            f"{query}: {cannot_open}",
        ),
        Case(
            "issue31-stats-polygon-file-symlink-loop",
            ("stats", str(DMA26), "--query", polygon, "--out", "out/i31-p-loop", "--quiet"),
            2,
            f"{polygon}: [region] polygon_file 'loop.toml': {LOOP}; give a path to a GeoJSON file",
        ),
        # pathlib's rglob does not follow a link to a directory: the dataset is read as it is.
        Case(
            "issue31-stats-dataset-with-a-link-to-its-parent",
            ("stats", str(parent.relative_to(work)), "--out", "out/i31-parent", "--quiet"),
            0,
        ),
        Case(
            "issue31-stats-dataset-with-a-broken-link",
            ("stats", str(broken.relative_to(work)), "--out", "out/i31-broken", "--quiet"),
            2,
            f"{stray}: a Parquet file the dataset manifest does not list (a dataset holds only "
            "what colregs9 ingest wrote); move it out of the dataset, or ingest its source",
        ),
    ]


def _duplicate_column_cases(work: Path) -> list[Case]:
    good = work / "datasets" / "good"
    canonical = pq.read_table(next(good.rglob("*.parquet")))
    lat = canonical.column("lat_deg")
    twice = canonical.append_column("lat_deg", lat)
    lat_twice = _write(work, "lat_twice.parquet", _parquet(twice))
    unread = canonical.append_column("note", lat).append_column("note", lat)
    unread_twice = _write(work, "unread_twice.parquet", _parquet(unread))
    inner = pa.StructArray.from_arrays([lat.combine_chunks()] * 2, names=["x", "x"])
    struct_twice = _write(
        work, "struct_twice.parquet", _parquet(canonical.append_column("extra", inner))
    )
    dropped = _spoilt_dataset(work, "dropped_lat_twice")
    pq.write_table(twice, dropped / "date=2024-09-09" / "lat_twice.parquet")
    rewritten = _spoilt_dataset(work, "rewritten_lat_twice")
    partition = next(rewritten.rglob("part-*.parquet"))
    pq.write_table(twice, partition)
    in_file = (
        f"{lat_twice}: the Parquet file has the column 'lat_deg' 2 times; write it again with "
        "each canonical column once"
    )
    in_dataset = (
        f"{partition.relative_to(work)}: has the column 'lat_deg' 2 times; not a file of this "
        "dataset: move it out, or re-create the dataset with colregs9 ingest"
    )
    cases = [
        Case(
            f"issue31-{command}-parquet-lat-twice",
            (command, lat_twice, "--out", f"out/i31-{command}-lat-twice", "--quiet"),
            2,
            in_file,
        )
        for command in ("stats", "replay", "ingest")
    ]
    return [
        *cases,
        # Columns colregs9 does not read may repeat: nothing it reads is in doubt.
        Case(
            "issue31-stats-parquet-unread-column-twice",
            ("stats", unread_twice, "--out", "out/i31-unread-twice", "--quiet"),
            0,
        ),
        Case(
            "issue31-stats-parquet-struct-field-twice",
            ("stats", struct_twice, "--out", "out/i31-struct-twice", "--quiet"),
            0,
        ),
        Case(
            "issue31-stats-dataset-with-a-file-dropped-in",
            ("stats", str(dropped.relative_to(work)), "--out", "out/i31-dropped", "--quiet"),
            2,
            f"{dropped.relative_to(work)}/date=2024-09-09/lat_twice.parquet: a Parquet file the "
            "dataset manifest does not list (a dataset holds only what colregs9 ingest wrote); "
            "move it out of the dataset, or ingest its source",
        ),
        Case(
            "issue31-stats-dataset-partition-lat-twice",
            ("stats", str(rewritten.relative_to(work)), "--out", "out/i31-rewritten", "--quiet"),
            2,
            in_dataset,
        ),
        Case(
            "issue31-ingest-into-dataset-partition-lat-twice",
            ("ingest", str(DMA22), "--out", str(rewritten.relative_to(work)), "--quiet"),
            2,
            in_dataset,
        ),
    ]


def _deep_toml_cases(work: Path) -> list[Case]:
    deep_array = _write(work, "queries/deep_array.toml", "a = " + "[" * 5000 + "]" * 5000 + "\n")
    deep_inline = _write(
        work, "queries/deep_inline.toml", "[x]\ny = " + "{a = " * 5000 + "1" + "}" * 5000 + "\n"
    )
    deep_map = _write(work, "deep_map.toml", "name = " + "[" * 5000 + "]" * 5000 + "\n")
    digits_map = _write(work, "digits_map.toml", "name = " + "1" * 5000 + "\n")
    mmsis = [257739000, 371420000, *range(219000000, 219009998)]
    wide = _write(
        work, "queries/wide_array.toml", f"[vessels]\nmmsi_include = {json.dumps(mmsis)}\n"
    )
    too_deep = (
        "arrays or inline tables nested hundreds of levels deep, too deep to read (colregs9's "
        "files nest them 2 deep at most)"
    )
    cases = [
        Case(
            f"issue31-{command}-query-nested-5000-deep",
            (command, str(DMA26), "--query", deep_array, "--out", f"out/i31-{command}", "--quiet"),
            2,
            f"{deep_array}: {too_deep}; fix the file",
        )
        for command in ("stats", "replay", "ingest")
    ]
    return [
        *cases,
        Case(
            "issue31-stats-query-inline-tables-5000-deep",
            ("stats", str(DMA26), "--query", deep_inline, "--out", "out/i31-inline", "--quiet"),
            2,
            f"{deep_inline}: {too_deep}; fix the file",
        ),
        Case(
            "issue31-simulate-scenario-nested-5000-deep",
            ("simulate", deep_array, "--out", "out/i31-deep.csv", "--quiet"),
            2,
            f"{deep_array}: {too_deep}; fix the file",
        ),
        Case(
            "issue31-demo-query-nested-5000-deep",
            ("demo", "--query", deep_array, "--out", "out/i31-demo-deep", "--quiet"),
            2,
            f"{deep_array}: {too_deep}; fix the file",
        ),
        Case(
            "issue31-stats-column-map-nested-5000-deep",
            ("stats", str(DMA26), "--columns", deep_map, "--out", "out/i31-map", "--quiet"),
            2,
            f"{deep_map}: {too_deep}; fix the map",
        ),
        Case(
            "issue31-stats-column-map-5000-digits",
            ("stats", str(DMA26), "--columns", digits_map, "--out", "out/i31-digits", "--quiet"),
            2,
            f"{digits_map}: a number of more than 4300 digits; give numbers of a sensible size",
        ),
        Case(
            "issue31-stats-query-10000-mmsis",
            ("stats", str(DMA26), "--query", wide, "--out", "out/i31-wide", "--quiet"),
            0,
        ),
    ]


def _pipe_and_long_name_cases(work: Path) -> list[Case]:
    query = _fifo(work, "queries/pipe.toml")
    polygon = _write(work, "queries/polygon_pipe.toml", "[region]\npolygon_file = 'pipe.toml'\n")
    manifest_pipe = _spoilt_dataset(work, "manifest_pipe")
    manifest = manifest_pipe / "colregs9-dataset.json"
    if manifest.is_file():
        manifest.unlink()
    _fifo(work, str(manifest.relative_to(work)))
    deep = _spoilt_dataset(work, "manifest_deep")
    (deep / "colregs9-dataset.json").write_text("[" * 5000 + "]" * 5000)
    deep_run_json = _write(work, "out_deep_run_json/run.json", '{"a": ' + "[" * 5000 + "]" * 5000)
    long_name = "x" * (NAME_MAX + 1) + ".csv"
    pipe_note = "a pipe or a device, not a file"
    return [
        Case(
            "issue31-stats-query-a-pipe",
            ("stats", str(DMA26), "--query", query, "--out", "out/i31-q-pipe", "--quiet"),
            2,
            f"{query}: {pipe_note}; give the TOML file",
        ),
        # Reading these pipes waited for a writer, for ever.
        Case(
            "issue31-stats-column-map-a-pipe",
            ("stats", str(DMA26), "--columns", query, "--out", "out/i31-map-pipe", "--quiet"),
            2,
            f"--columns {query}: {pipe_note}; give the map's TOML file",
        ),
        Case(
            "issue31-stats-polygon-file-a-pipe",
            ("stats", str(DMA26), "--query", polygon, "--out", "out/i31-p-pipe", "--quiet"),
            2,
            f"{polygon}: [region] polygon_file 'pipe.toml' is {work.resolve() / query}, "
            f"{pipe_note}; give a GeoJSON file",
        ),
        Case(
            "issue31-stats-dataset-manifest-a-pipe",
            ("stats", str(manifest_pipe.relative_to(work)), "--out", "out/i31-m", "--quiet"),
            2,
            f"{manifest.relative_to(work)}: not a file; restore the dataset manifest, or "
            "re-create the dataset with colregs9 ingest",
        ),
        Case(
            "issue31-stats-dataset-manifest-nested-5000-deep",
            ("stats", str(deep.relative_to(work)), "--out", "out/i31-m-deep", "--quiet"),
            2,
            f"{deep.relative_to(work)}/colregs9-dataset.json: the manifest is nested too deeply "
            "to be one; restore it, or re-create the dataset with colregs9 ingest",
        ),
        Case(
            "issue31-stats-out-holds-run-json-nested-5000-deep",
            ("stats", str(DMA26), "--out", str(Path(deep_run_json).parent), "--quiet"),
            2,
            "out_deep_run_json: --out is not a colregs9 report and holds 1 item(s): run.json; "
            "give a new or empty directory, or add --overwrite to write the report beside them "
            "(they are kept)",
        ),
        Case(
            "issue31-stats-ais-name-too-long",
            ("stats", long_name, "--out", "out/i31-long", "--quiet"),
            2,
            f"{long_name}: a file name longer than the file system allows; give a shorter one",
        ),
        Case(
            "issue31-ingest-out-name-too-long",
            ("ingest", str(DMA26), "--out", long_name, "--quiet"),
            2,
            f"{long_name}: a file name longer than the file system allows; give a shorter one",
        ),
    ]


TRACEBACK_CASES = {
    c.id: c
    for c in (
        *_loop_cases(WORK),
        *_duplicate_column_cases(WORK),
        *_deep_toml_cases(WORK),
        *_pipe_and_long_name_cases(WORK),
    )
}


@pytest.fixture(scope="module")
def traceback_results(work: Path) -> dict[str, dict[str, object]]:
    listed = work / "traceback_cases.json"
    listed.write_text(
        json.dumps(
            [{"id": c.id, "args": list(c.args), "cwd": str(work)} for c in TRACEBACK_CASES.values()]
        )
    )
    answers = work / "traceback_results.json"
    subprocess.run(
        [sys.executable, str(DRIVER), str(listed), str(answers)], check=True, timeout=600
    )
    return json.loads(answers.read_text())


@pytest.mark.parametrize("case_id", list(TRACEBACK_CASES))
def test_once_a_traceback(case_id: str, traceback_results, work: Path) -> None:
    case = TRACEBACK_CASES[case_id]
    result = traceback_results[case_id]
    _check(case, result["code"], result["stdout"], result["stderr"], result["escaped"], work)
    if case.code:
        assert result["stderr"] == f"Error: {case.names}\n"
