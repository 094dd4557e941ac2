"""Query TOML parsing and the region/time/vessel filters."""

from __future__ import annotations

import json
import pickle
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from colregs9_cli.errors import Colregs9Error, InputFileError, QueryError
from colregs9_cli.query import Region, everything_query, load_query

from fixture_files import ROOT

SQUARE = {
    "type": "Polygon",
    "coordinates": [[[9.9, 57.0], [10.0, 57.0], [10.0, 57.1], [9.9, 57.0]]],
}


def write(tmp_path: Path, text: str, name: str = "q.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_saved_queries() -> None:
    aalborg = load_query(ROOT / "queries" / "aalborg_fjord.toml")
    assert aalborg.name == "aalborg_fjord" and "Rule 9" in aalborg.description
    r = aalborg.region
    assert r is not None
    assert (r.lat_min, r.lat_max, r.lon_min, r.lon_max) == (
        57.044196,
        57.062865,
        9.909933,
        9.971545,
    )
    frame = aalborg.frame()
    assert frame is not None
    assert frame.lat0_deg == pytest.approx((57.044196 + 57.062865) / 2)
    limfjorden = load_query(ROOT / "queries" / "limfjorden.toml")
    assert limfjorden.region == Region(56.5, 57.2, 8.2, 10.4)
    assert everything_query().name == "all" and everything_query().frame() is None


def test_full_query(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """
name = "test"
[region]
lat_min = 57.0
lat_max = 57.1
lon_min = 9.9
lon_max = 10.0
[time]
start = 2024-09-09T00:00:00Z
end = "2024-09-09T03:00:00+02:00"
[vessels]
mobile_types = ["Class A"]
mmsi_exclude = [219000179]
ship_types = ["cargo"]
length_min_m = 20.0
[replay]
cpa_req_m = 150.0
""",
    )
    query = load_query(path)
    assert query.time.start == datetime(2024, 9, 9, tzinfo=UTC)
    assert query.time.end == datetime(2024, 9, 9, 1, tzinfo=UTC)  # +02:00 to UTC
    assert query.tables["replay"]["cpa_req_m"] == 150.0
    selected = query.vessels.selects(
        [219281000, 219000179, 219281000, 219281000],
        ["Class A", "Class A", "Class B", "Class A"],
        ["Cargo", "Cargo", "Cargo", "Cargo"],
        [238.0, 238.0, 238.0, np.nan],
    )
    assert selected.tolist() == [True, False, False, False]
    assert query.source == path
    # A query goes to Dask workers whole, its stage tables read-only again there.
    copy = pickle.loads(pickle.dumps(query))
    assert copy == query
    assert copy.tables["replay"]["cpa_req_m"] == 150.0
    with pytest.raises(TypeError):
        copy.tables["replay"]["cpa_req_m"] = 1.0  # type: ignore[index]


def test_start_must_precede_end(tmp_path: Path) -> None:
    path = write(tmp_path, "[time]\nstart = 2024-09-09T02:00:00Z\nend = 2024-09-09T01:00:00Z\n")
    with pytest.raises(QueryError, match=r"\[time\] time start .* is not before end"):
        load_query(path)


def test_syntax_error(tmp_path: Path) -> None:
    path = write(tmp_path, "name = \n")
    with pytest.raises(QueryError, match=r"q\.toml: TOML syntax error"):
        load_query(path)


def test_missing_query_file(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="no such file"):
        load_query(tmp_path / "none.toml")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("regoin = 1\n", "unknown key 'regoin'"),
        (
            "[region]\nlat_min = 1\nlat_max = 2\nlon_min = 1\nlon_max = 2\nlatmax = 3\n",
            r"\[region\] unknown key 'latmax'",
        ),
        ("[time]\nbegin = 2024-01-01T00:00:00Z\n", r"\[time\] unknown key 'begin'"),
        ("[vessels]\nmmsi = [1]\n", r"\[vessels\] unknown key 'mmsi'"),
        ("[vessels]\nmobile_types = ['Base Station']\n", "mobile_types contains 'Base Station'"),
        ("[vessels]\nmmsi_include = [1234]\n", "mmsi_include contains 1234"),
        ("[vessels]\nlength_min_m = 50.0\nlength_max_m = 10.0\n", "length_min_m = 50.0 is above"),
        ("[time]\nstart = 'yesterday'\n", "is not an ISO 8601 time"),
        ("name = 'a b'\n", "name = 'a b'"),
        ("[region]\nlat_min = 1.0\n", "but not lat_max"),
    ],
)
def test_bad_keys_and_values(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(QueryError, match=message):
        load_query(write(tmp_path, text))


def test_lat_min_above_lat_max(tmp_path: Path) -> None:
    path = write(
        tmp_path, "[region]\nlat_min = 57.2\nlat_max = 56.5\nlon_min = 8.2\nlon_max = 10.4\n"
    )
    with pytest.raises(
        QueryError, match=r"q.toml: \[region\] lat_min = 57.2 is not below lat_max = 56.5"
    ):
        load_query(path)


def test_box_contains_is_inclusive_and_nan_safe() -> None:
    region = Region(57.0, 57.1, 9.9, 10.0)
    inside = region.contains([57.0, 57.05, 57.1, 57.2, np.nan], [9.9, 9.95, 10.0, 9.95, 9.95])
    assert inside.tolist() == [True, True, True, False, False]


def test_polygon_region_inline_and_from_file(tmp_path: Path) -> None:
    inline = write(tmp_path, f"[region]\npolygon = '{json.dumps(SQUARE)}'\n")
    query = load_query(inline)
    region = query.region
    assert region is not None and region.polygon is not None
    assert (region.lat_min, region.lat_max, region.lon_min, region.lon_max) == (
        57.0,
        57.1,
        9.9,
        10.0,
    )
    # The triangle's hypotenuse runs from (9.9, 57.0) to (10.0, 57.1): below it is inside.
    assert region.contains([57.01, 57.09], [9.99, 9.91]).tolist() == [True, False]
    (tmp_path / "area.geojson").write_text(json.dumps({"type": "Feature", "geometry": SQUARE}))
    from_file = load_query(write(tmp_path, "[region]\npolygon_file = 'area.geojson'\n", "f.toml"))
    assert from_file.region is not None and from_file.region.polygon is not None
    assert from_file.region.polygon.equals(region.polygon)


def test_bad_polygons(tmp_path: Path) -> None:
    point = json.dumps({"type": "Point", "coordinates": [9.9, 57.0]})
    with pytest.raises(QueryError, match="geometry type 'Point'"):
        load_query(write(tmp_path, f"[region]\npolygon = '{point}'\n"))
    with pytest.raises(QueryError, match="not valid JSON"):
        load_query(write(tmp_path, "[region]\npolygon = '{nope'\n"))
    with pytest.raises(InputFileError, match="no such file"):
        load_query(write(tmp_path, "[region]\npolygon_file = 'none.geojson'\n"))


@pytest.mark.parametrize("value", ["NaN", "Infinity", '"10"'])
def test_a_polygon_vertex_that_is_not_a_finite_number(tmp_path: Path, value: str) -> None:
    import warnings

    polygon = f'{{"type":"Polygon","coordinates":[[[10,57],[11,57],[{value},58],[10,57]]]}}'
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(QueryError, match="is not a finite number"):
            load_query(write(tmp_path, f"[region]\npolygon = '{polygon}'\n"))


def test_time_bounds_finer_than_a_millisecond_keep_exactly_the_rows_inside(tmp_path: Path) -> None:
    from datetime import UTC, datetime

    from colregs9_cli.query import ms_at_or_after

    assert ms_at_or_after(datetime(2023, 1, 11, 0, 0, 1, 100, tzinfo=UTC)) == 1673395201001
    assert ms_at_or_after(datetime(2023, 1, 11, 0, 0, 1, tzinfo=UTC)) == 1673395201000
    assert ms_at_or_after(datetime(1969, 12, 31, 23, 59, 59, 999_500, tzinfo=UTC)) == 0


def _outsize_queries() -> list[tuple[str, str]]:
    polygon = json.dumps({"type": "Polygon", "coordinates": [[[0, 1], [2, 2], [3, 1], [0, 1]]]})
    big, huge = "9" * 400, "9" * 5000
    return [
        (f"[region]\npolygon = '{polygon.replace('[0, 1]', f'[{big}, 1]', 1)}'\n", "polygon"),
        (f"[region]\npolygon = '{polygon.replace('[0, 1]', f'[{huge}, 1]', 1)}'\n", "4300"),
        (f"[vessels]\nlength_min_m = {huge}\n", "4300 digits"),
        ('[region]\npolygon_file = "a\\u0000b"\n', "polygon_file"),
        (f'[region]\npolygon_file = "{"a" * 5000}"\n', "polygon_file"),
    ]


@pytest.mark.parametrize(("text", "names"), _outsize_queries())
def test_outsize_query_values_are_one_query_error(tmp_path: Path, text: str, names: str) -> None:
    path = tmp_path / "q.toml"
    path.write_text(text)
    with pytest.raises(Colregs9Error, match=names):
        load_query(path)
