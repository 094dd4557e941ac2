"""Coverage is what a cell says it covers (M_COVR), and where cells overlap the more detailed
one decides the depth (navigational purpose, then compilation scale)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyogrio
import pytest
import shapely

from colregs9_cli.charts.cells import cell_purpose
from colregs9_cli.charts.gdal_layers import S57_OPEN_OPTIONS
from colregs9_cli.charts.sources import read_charts
from colregs9_cli.charts.water import Chart, load_chart, project_charts
from colregs9_cli.geo import LocalFrame

from fixture_files import SANDIEGO_ENC


def test_sandiego_coverage_is_its_m_covr() -> None:
    chart = load_chart([SANDIEGO_ENC])
    meta, _, wkb, fields = pyogrio.raw.read(SANDIEGO_ENC, layer="M_COVR")
    catcov = np.asarray(dict(zip(meta["fields"], fields, strict=True))["CATCOV"])
    polygons = shapely.from_wkb(wkb)
    expected = shapely.difference(
        shapely.union_all(polygons[catcov == 1]), shapely.union_all(polygons[catcov == 2])
    )

    def to_frame(xy: np.ndarray) -> np.ndarray:
        north, east = chart.frame.to_local(xy[:, 1], xy[:, 0])
        return np.column_stack([east, north])

    expected_m = shapely.transform(expected, to_frame)
    assert chart.coverage.area == pytest.approx(expected_m.area, rel=1e-9)
    assert shapely.symmetric_difference(chart.coverage, expected_m).area < 1.0  # m²


FRAME = LocalFrame(57.0, 10.0)


def _cell(tmp_path: Path, name: str, box: list[float], depth: float, purpose: int, scale: int):
    lon0, lat0, lon1, lat1 = box
    ring = [[lon0, lat0], [lon1, lat0], [lon1, lat1], [lon0, lat1], [lon0, lat0]]
    polygon = {"type": "Polygon", "coordinates": [ring]}
    features = [
        {
            "type": "Feature",
            "properties": {"OBJL": "DEPARE", "DRVAL1": depth, "DRVAL2": depth + 2.0},
            "geometry": polygon,
        },
        {
            "type": "Feature",
            "properties": {
                "OBJL": "M_COVR",
                "DRVAL1": None,
                "CATCOV": 1,
                "INTU": purpose,
                "CSCL": scale,
            },
            "geometry": polygon,
        },
    ]
    path = tmp_path / f"{name}.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.mark.parametrize("detailed_first", [True, False])
def test_overlapping_cells_resolve_to_the_detailed_one(
    tmp_path: Path, detailed_first: bool
) -> None:
    # A coarse approach cell says 5.4 m over a large square; a harbour cell inside it says 3.6 m.
    coarse = _cell(tmp_path, "coarse", [9.98, 56.99, 10.02, 57.01], 5.4, purpose=3, scale=80_000)
    harbour = _cell(
        tmp_path, "harbour", [9.995, 56.997, 10.005, 57.003], 3.6, purpose=5, scale=12_000
    )
    paths = [harbour, coarse] if detailed_first else [coarse, harbour]
    chart = load_chart(paths, FRAME)
    water = chart.navigable_water(5.0)
    # the harbour's water, charted at 3.6 m by the detailed cell, is not navigable at 5 m
    assert not shapely.contains_xy(water, 0.0, 0.0)
    # outside the harbour cell the coarse cell's 5.4 m counts
    assert shapely.contains_xy(water, 0.0, 900.0)
    # both together cover the coarse square; the harbour square is charted, shallow
    assert chart.covers(0.0, 0.0)[0] and chart.covers(0.0, 900.0)[0]
    harbour_only = load_chart([harbour], FRAME)
    assert chart.navigable_water(3.0).contains(harbour_only.coverage.buffer(-1.0))


def _polygon(ring: list[list[float]]) -> dict:
    return {"type": "Polygon", "coordinates": [[*ring, ring[0]]]}


def _write(path: Path, features: list[tuple[dict, dict]]) -> Path:
    collection = {
        "type": "FeatureCollection",
        "features": [
            {"type": "Feature", "properties": props, "geometry": geometry}
            for props, geometry in features
        ],
    }
    path.write_text(json.dumps(collection), encoding="utf-8")
    return path


def test_a_coarse_area_that_touches_the_detailed_cell_along_its_edge_is_kept(
    tmp_path: Path,
) -> None:
    # The coarse cell's one 5.4 m area is a tongue inside the harbour cell, whose top edge is
    # the harbour's north edge, joined to a block east of the harbour. Clipped to where the
    # coarse cell decides, it is the block plus the line along that edge: GEOS returns a
    # geometry collection, which was dropped as "not a polygon", and the block's 0.68 km² of
    # 5.4 m water with it.
    harbour_ring = [[10.0, 57.0], [10.01, 57.0], [10.01, 57.01], [10.0, 57.01]]
    harbour = _write(
        tmp_path / "harbour.geojson",
        [
            ({"OBJL": "DEPARE", "DRVAL1": 3.6}, _polygon(harbour_ring)),
            ({"OBJL": "M_COVR", "CATCOV": 1, "INTU": 5, "CSCL": 12_000}, _polygon(harbour_ring)),
        ],
    )
    tongue_and_block = [
        [10.0, 57.006],
        [10.0, 57.01],
        [10.01, 57.01],
        [10.02, 57.01],
        [10.02, 57.0],
        [10.01, 57.0],
        [10.01, 57.006],
    ]
    coarse_ring = [[9.99, 56.99], [10.03, 56.99], [10.03, 57.02], [9.99, 57.02]]
    coarse = _write(
        tmp_path / "coarse.geojson",
        [
            ({"OBJL": "DEPARE", "DRVAL1": 5.4}, _polygon(tongue_and_block)),
            ({"OBJL": "M_COVR", "CATCOV": 1, "INTU": 3, "CSCL": 80_000}, _polygon(coarse_ring)),
        ],
    )
    frame = LocalFrame(57.005, 10.01)
    chart = load_chart([coarse, harbour], frame)
    block_north, block_east = frame.to_local(57.005, 10.015)
    harbour_north, harbour_east = frame.to_local(57.008, 10.005)
    water = chart.navigable_water(5.0)
    assert shapely.contains_xy(water, block_east, block_north)
    assert not shapely.contains_xy(water, harbour_east, harbour_north)  # the tongue: 3.6 m
    assert chart.navigable_area_km2(5.0) == pytest.approx(0.6767, abs=1e-3)
    assert len(chart.depth_areas) == 2


@pytest.mark.parametrize("shallow_first", [True, False])
def test_charts_without_metadata_keep_the_given_order(tmp_path: Path, shallow_first: bool) -> None:
    # Two GeoJSON charts of the same square, no M_COVR, no purpose or scale: the first given
    # decides, and the other adds nothing inside its coverage.
    ring = [[9.99, 56.995], [10.01, 56.995], [10.01, 57.005], [9.99, 57.005]]
    shallow = _write(
        tmp_path / "shallow.geojson", [({"OBJL": "DEPARE", "DRVAL1": 3.6}, _polygon(ring))]
    )
    deep = _write(tmp_path / "deep.geojson", [({"OBJL": "DEPARE", "DRVAL1": 5.4}, _polygon(ring))])
    chart = load_chart([shallow, deep] if shallow_first else [deep, shallow], FRAME)
    assert chart.detail_order[0] == (shallow if shallow_first else deep)
    assert bool(shapely.contains_xy(chart.navigable_water(5.0), 0.0, 0.0)) is not shallow_first
    assert len(chart.depth_areas) == 1


@pytest.fixture(scope="module")
def sandiego() -> Chart:
    return load_chart([SANDIEGO_ENC])


def test_a_coarse_chart_over_the_sandiego_cell_decides_only_outside_it(
    tmp_path: Path, sandiego: Chart
) -> None:
    # A coarse (coastal, 1:80,000) chart that says 20 m everywhere around and over the harbour
    # cell, given first: inside the cell's M_COVR the cell's depths decide, outside it 20 m.
    ring = [[-117.35, 32.5], [-117.0, 32.5], [-117.0, 32.8], [-117.35, 32.8]]
    coarse = _write(
        tmp_path / "coastal.geojson",
        [
            ({"OBJL": "DEPARE", "DRVAL1": 20.0}, _polygon(ring)),
            ({"OBJL": "M_COVR", "CATCOV": 1, "INTU": 3, "CSCL": 80_000}, _polygon(ring)),
        ],
    )
    both = load_chart([coarse, SANDIEGO_ENC], sandiego.frame)
    assert both.detail_order == (SANDIEGO_ENC, coarse)
    water = both.navigable_water(5.0)
    inside = shapely.intersection(water, sandiego.coverage)
    own = sandiego.navigable_water(5.0)
    assert shapely.symmetric_difference(inside, own).area < 1e-6 * own.area
    assert inside.area < 0.5 * sandiego.coverage.area  # not the coarse cell's 20 m
    outside = shapely.difference(both.coverage, sandiego.coverage)
    assert shapely.difference(outside, water).area < 1.0  # m²: all 20 m water
    assert both.coverage_by_chart[0].equals(sandiego.coverage)


def test_a_cells_purpose_is_its_dsid_else_its_name() -> None:
    assert cell_purpose(5, Path("XX1ABCDE.000")) == 5
    assert cell_purpose(None, Path("US4CA11M.000")) == 4
    assert cell_purpose("", Path("chart.000")) == 0
    assert cell_purpose(9, Path("US3XX.000")) == 3  # INTU outside 1..6 is not a purpose
    assert read_charts([SANDIEGO_ENC]).features[0].purpose == 5


def _export_like_ogr2ogr(cell: Path, out: Path) -> Path:
    """The cell's layers as ``ogr2ogr -f GPKG out.gpkg CELL.000`` writes them: one layer per
    object class, named after it, with OBJL (its numeric code), and the DSID table. List and
    string fields are left out (GDAL's GeoPackage driver cannot take lists)."""
    layers = {str(name) for name, _ in pyogrio.list_layers(cell)}
    wanted = ["DSID", "M_COVR", "DEPARE", "DRGARE", "LNDARE", "PONTON", "HULKES", "FLODOC"]
    wanted += ["DRYDOC", "OBSTRN", "WRECKS", "UWTROC"]
    for index, layer in enumerate(name for name in wanted if name in layers):
        meta, _, wkb, fields = pyogrio.raw.read(
            cell, layer=layer, read_geometry=layer != "DSID", **S57_OPEN_OPTIONS
        )
        keep = [i for i, values in enumerate(fields) if values.dtype != object]
        pyogrio.raw.write(
            out,
            wkb,
            [fields[i] for i in keep],
            [meta["fields"][i] for i in keep],
            layer=layer,
            driver="GPKG",
            geometry_type=None if layer == "DSID" else "Unknown",
            crs=None if layer == "DSID" else meta["crs"],
            append=index > 0,
        )
    return out


def test_a_geopackage_exported_from_the_cell_reads_like_the_cell(
    tmp_path: Path, sandiego: Chart
) -> None:
    exported = _export_like_ogr2ogr(SANDIEGO_ENC, tmp_path / "US5CA72M.gpkg")
    assert "DRVAL1" not in pyogrio.read_info(exported, layer="LNDARE")["fields"]
    source = read_charts([exported])
    (features,) = source.features
    assert (features.purpose, features.scale) == (5, 12_000.0)  # from its DSID table
    chart = project_charts(source, sandiego.frame)
    assert chart.coverage.area == pytest.approx(sandiego.coverage.area, rel=1e-12)
    assert dict(chart.layer_counts) == dict(sandiego.layer_counts)
    assert chart.navigable_area_km2(2.0) == pytest.approx(sandiego.navigable_area_km2(2.0))


def test_the_source_bounds_reach_the_m_covr(tmp_path: Path) -> None:
    # A chart whose M_COVR reaches past its one depth area: the run's frame and the box
    # compared with the AIS take the coverage, not only the features.
    small = [[10.0, 57.0], [10.01, 57.0], [10.01, 57.01], [10.0, 57.01]]
    large = [[9.98, 56.99], [10.03, 56.99], [10.03, 57.02], [9.98, 57.02]]
    path = _write(
        tmp_path / "c.geojson",
        [
            ({"OBJL": "DEPARE", "DRVAL1": 3.0}, _polygon(small)),
            ({"OBJL": "M_COVR", "CATCOV": 1}, _polygon(large)),
        ],
    )
    assert read_charts([path]).bounds_wgs84() == pytest.approx((56.99, 57.02, 9.98, 10.03))
