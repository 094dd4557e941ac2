"""Chart loading (S-57, GeoJSON, GeoPackage), navigable water and coverage."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
import shapely
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from pyogrio.raw import read, write

from colregs9_cli.charts.sources import read_charts
from colregs9_cli.charts.water import HAZARD_RADIUS_M, Chart, load_chart
from colregs9_cli.core.manoeuvrability import (
    ManoeuvrabilityParams,
    SwingModel,
    VesselState,
    assess_manoeuvrability,
)
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import ChartError, ParameterError
from colregs9_cli.geo import LocalFrame
from colregs9_cli.report.chart_plot import draw_assessment, draw_chart

ENC = Path(__file__).resolve().parents[1] / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"


@pytest.fixture(scope="module")
def enc() -> Chart:
    return load_chart([ENC])


def test_enc_layer_counts(enc: Chart) -> None:
    # Cross-checked with `len(pyogrio.raw.read(ENC, layer=L)[1])` for each layer; DEPARE's 239
    # is also the figure in the issue.
    assert dict(enc.layer_counts) == {
        "DEPARE": 239,
        "DRGARE": 10,
        "LNDARE": 28,
        "PONTON": 34,
        "HULKES": 1,
        "OBSTRN": 45,
        "WRECKS": 3,
        "UWTROC": 9,
    }
    assert len(enc.depth_areas) == 239 + 10
    assert (enc.kinds == "DRGARE").sum() == 10


def test_enc_depth_range(enc: Chart) -> None:
    raw = np.concatenate(
        [read(ENC, layer=layer, columns=["DRVAL1"])[3][0] for layer in ("DEPARE", "DRGARE")]
    )
    assert enc.depth_range_m() == (raw.min(), raw.max()) == (-0.5, 9.1)


def test_enc_extent_and_coverage(enc: Chart) -> None:
    assert read_charts([ENC]).bounds_wgs84() == pytest.approx((38.925, 39.0, -76.5, -76.425))
    assert enc.bounds_wgs84() == pytest.approx((38.925, 39.0, -76.5, -76.425), abs=1e-6)
    # The cell's own coverage record M_COVR, projected the same way, has the same area: depth
    # areas, land and structures tile the cell.
    m_covr = shapely.from_wkb(read(ENC, layer="M_COVR")[2])
    projected = shapely.transform(
        m_covr, lambda xy: np.column_stack(enc.frame.to_local(xy[:, 1], xy[:, 0])[::-1])
    )
    assert enc.coverage.area == pytest.approx(shapely.area(projected).sum(), rel=1e-4)
    assert enc.covers(0.0, 0.0)
    assert not enc.covers(np.array([0.0, 9e3]), np.array([9e3, 0.0])).any()


def test_navigable_water_shrinks_with_draught(enc: Chart) -> None:
    areas = [enc.navigable_area_km2(draught) for draught in (0.0, 2.0, 5.0, 8.0, 9.5)]
    assert all(a > b for a, b in itertools.pairwise(areas))
    assert areas[-1] == 0.0
    assert enc.navigable_area_km2(4.0, ukc_m=1.0) == pytest.approx(areas[2])
    assert shapely.difference(enc.navigable_water(2.0), enc.coverage).area < 1e-3


def test_navigable_water_is_cached_per_draught(enc: Chart) -> None:
    assert enc.navigable_water(5.0) is enc.navigable_water(5.0)
    assert enc.navigable_water(5.0) is not enc.navigable_water(5.0, 0.5)


def test_negative_draught_or_ukc_is_an_error(enc: Chart) -> None:
    with pytest.raises(ParameterError, match="draught -1"):
        enc.navigable_water(-1.0)
    with pytest.raises(ParameterError, match=r"under-keel clearance -0\.5"):
        enc.navigable_water(5.0, -0.5)


def _feature(objl: object, geometry: dict, **properties: object) -> dict:
    return {
        "type": "Feature",
        "properties": {"OBJL": objl, **properties},
        "geometry": geometry,
    }


def _box(lon0: float, lat0: float, lon1: float, lat1: float) -> dict:
    return shapely.geometry.mapping(shapely.box(lon0, lat0, lon1, lat1))


def _write_geojson(path: Path, features: list[dict]) -> Path:
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def _modelled_features() -> list[dict]:
    return [
        _feature("DEPARE", _box(9.90, 57.04, 9.95, 57.06), DRVAL1=8.0, DRVAL2=10.0),
        _feature(42, _box(9.95, 57.04, 9.97, 57.06), DRVAL1=2.0, DRVAL2=5.0),
        _feature("LNDARE", _box(9.90, 57.06, 9.97, 57.07), DRVAL1=None),
    ]


def test_geojson_with_acronyms_and_numeric_codes(tmp_path: Path) -> None:
    chart = load_chart([_write_geojson(tmp_path / "m.geojson", _modelled_features())])
    assert dict(chart.layer_counts) == {"DEPARE": 2, "LNDARE": 1}
    assert chart.depth_range_m() == (2.0, 8.0)
    deep_only = chart.navigable_area_km2(5.0)
    both = chart.navigable_area_km2(2.0)
    assert 0.0 < deep_only < both
    assert chart.frame.lat0_deg == pytest.approx(57.055)


def test_several_charts_are_merged(tmp_path: Path) -> None:
    west = _write_geojson(tmp_path / "w.geojson", _modelled_features()[:1])
    east = _write_geojson(tmp_path / "e.geojson", _modelled_features()[1:])
    merged = load_chart([west, east])
    single = load_chart([_write_geojson(tmp_path / "all.geojson", _modelled_features())])
    assert dict(merged.layer_counts) == dict(single.layer_counts)
    assert merged.coverage.area == pytest.approx(single.coverage.area)


def test_hazards_block_only_deeper_draughts(tmp_path: Path) -> None:
    point = {"type": "Point", "coordinates": [9.92, 57.05]}
    features = [*_modelled_features(), _feature("OBSTRN", point, DRVAL1=None, VALSOU=3.0)]
    chart = load_chart([_write_geojson(tmp_path / "h.geojson", features)])
    plain = load_chart([_write_geojson(tmp_path / "p.geojson", _modelled_features())])
    assert chart.navigable_area_km2(2.5) == pytest.approx(plain.navigable_area_km2(2.5))
    hole_km2 = plain.navigable_area_km2(5.0) - chart.navigable_area_km2(5.0)
    # A buffered point: a polygon inscribed in the 10 m circle.
    assert hole_km2 * 1e6 == pytest.approx(math.pi * HAZARD_RADIUS_M**2, rel=0.01)


def test_geopackage_in_a_projected_crs(tmp_path: Path) -> None:
    from pyproj import Transformer

    to_utm = Transformer.from_crs("EPSG:4326", "EPSG:32632", always_xy=True)
    features = _modelled_features()
    geometries = [
        shapely.transform(
            shapely.geometry.shape(f["geometry"]),
            lambda xy: np.column_stack(to_utm.transform(xy[:, 0], xy[:, 1])),
        )
        for f in features
    ]
    path = tmp_path / "m.gpkg"
    write(
        path,
        shapely.to_wkb(np.array(geometries, dtype=object)),
        [np.array(["DEPARE", "DEPARE", "LNDARE"], dtype=object), np.array([8.0, 2.0, np.nan])],
        ["OBJL", "DRVAL1"],
        driver="GPKG",
        geometry_type="Polygon",
        crs="EPSG:32632",
    )
    from_gpkg = load_chart([path])
    from_geojson = load_chart([_write_geojson(tmp_path / "m.geojson", features)])
    assert from_gpkg.navigable_area_km2(5.0) == pytest.approx(
        from_geojson.navigable_area_km2(5.0), rel=1e-6
    )


def test_a_text_file_named_000_is_not_a_chart(tmp_path: Path) -> None:
    path = tmp_path / "notes.000"
    path.write_text("this is not an ENC\n")
    with pytest.raises(ChartError, match=r"notes\.000"):
        load_chart([path])


def test_a_random_geojson_is_not_a_chart(tmp_path: Path) -> None:
    path = _write_geojson(
        tmp_path / "cafes.geojson",
        [
            {
                "type": "Feature",
                "properties": {"name": "cafe"},
                "geometry": {"type": "Point", "coordinates": [9.9, 57.0]},
            }
        ],
    )
    with pytest.raises(ChartError, match=r"cafes.geojson.*no column OBJL"):
        load_chart([path])


def test_a_geojson_without_drval1_names_the_column(tmp_path: Path) -> None:
    features = [_feature("DEPARE", _box(9.90, 57.04, 9.95, 57.06), DEPTH=8.0)]
    path = _write_geojson(tmp_path / "nodepth.geojson", features)
    with pytest.raises(ChartError, match=r"nodepth.geojson.*no column DRVAL1"):
        load_chart([path])


def test_a_chart_without_depth_areas_is_an_error(tmp_path: Path) -> None:
    path = _write_geojson(tmp_path / "land.geojson", _modelled_features()[2:])
    with pytest.raises(ChartError, match="no depth areas"):
        load_chart([path])


def test_missing_and_unknown_files(tmp_path: Path) -> None:
    with pytest.raises(ChartError, match="no such chart file"):
        load_chart([tmp_path / "absent.000"])
    other = tmp_path / "chart.shp.zip"
    other.write_bytes(b"PK")
    with pytest.raises(ChartError, match="unknown chart type"):
        load_chart([other])
    for name in ("broken.geojson", "fake.gpkg"):
        (tmp_path / name).write_text("{nope")
        with pytest.raises(ChartError, match="not a chart GDAL can open") as raised:
            load_chart([tmp_path / name])
        assert "DRIVER" not in str(raised.value)  # GDAL's hint: colregs9 takes no prefix
    update = tmp_path / "US5CA72M.002"
    update.write_bytes(b"")
    with pytest.raises(ChartError, match=r"an S-57 update file \(\.002\); give its base cell"):
        load_chart([update])


def test_draw_chart_shades_depth_areas_by_drval1(enc: Chart) -> None:
    figure = Figure()
    ax = figure.subplots()
    draw_chart(ax, enc, 5.0)
    by_gid = {c.get_gid(): c for c in ax.collections}
    assert set(by_gid) == {"depth-areas", "land", "navigable-water"}
    np.testing.assert_array_equal(by_gid["depth-areas"].get_array(), enc.drval1_m)
    assert len(by_gid["depth-areas"].get_paths()) == 249
    # Outlined, not tinted, so the depth colours match the colour bar.
    assert len(by_gid["navigable-water"].get_facecolor()) == 0
    FigureCanvasAgg(figure).draw()


def test_draw_assessment_colours_ellipses_by_flag(enc: Chart) -> None:
    frame = LocalFrame(38.9625, -76.4625)
    assert enc.frame == frame
    assessment = assess_manoeuvrability(
        enc,
        VesselState(3014.5, -1696.3, 145.0, 3.6),
        VesselDimensions(50.0, 9.0, 5.0, defaulted=(), basis=""),
        ManoeuvrabilityParams(swing_model=SwingModel.FIXED),
    )
    figure = Figure()
    ax = figure.subplots()
    draw_assessment(ax, assessment)
    by_gid = {c.get_gid(): c for c in ax.collections}
    red = assessment.restricted & assessment.covered
    assert len(by_gid["restricted-ellipses"].get_paths()) == red.sum() > 0
    assert len(by_gid["clear-ellipses"].get_paths()) == (~red).sum() > 0
    # The few restricted ellipses are not hidden under the clear ones.
    assert by_gid["restricted-ellipses"].get_zorder() > by_gid["clear-ellipses"].get_zorder()
    lines = {line.get_label(): line for line in ax.get_lines()}
    np.testing.assert_allclose(
        lines["cw arc"].get_xdata(), assessment.east_m[assessment.arc == "cw"]
    )
    FigureCanvasAgg(figure).draw()


def _two_squares(tmp_path: Path, gap_m: float) -> Chart:
    """Two 100 m depth squares side by side (east–west), ``gap_m`` apart, in a metric CRS."""
    utm_box = shapely.box(500_000.0, 6_300_000.0, 500_100.0, 6_300_100.0)
    east = shapely.affinity.translate(utm_box, xoff=100.0 + gap_m)
    features = [
        _feature("DEPARE", shapely.geometry.mapping(square), DRVAL1=5.0, DRVAL2=10.0)
        for square in (utm_box, east)
    ]
    path = tmp_path / f"gap-{gap_m}.geojson"
    path.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32632"}},
                "features": features,
            }
        )
    )
    return load_chart([path])


def test_a_sliver_gap_between_depth_areas_is_closed(tmp_path: Path) -> None:
    # 1 cm: the kind of seam a coordinate conversion leaves; closed (SLIVER_TOLERANCE_M 0.1 m)
    chart = _two_squares(tmp_path, 0.01)
    water = chart.navigable_water(5.0)
    assert shapely.get_num_geometries(water) == 1
    assert shapely.get_num_interior_rings(water) == 0
    # the closing adds the seam (1 cm x 100 m) and moves nothing else
    squares_m2 = shapely.area(chart.depth_areas).sum()
    assert water.area == pytest.approx(squares_m2 + 0.01 * 100.0, abs=0.05)
    assert shapely.difference(water, chart.coverage).area == pytest.approx(1.0, abs=0.05)


def test_a_real_gap_between_depth_areas_stays(tmp_path: Path) -> None:
    chart = _two_squares(tmp_path, 1.0)
    water = chart.navigable_water(5.0)
    assert shapely.get_num_geometries(water) == 2
    assert water.area == pytest.approx(shapely.area(chart.depth_areas).sum(), abs=1e-6)
