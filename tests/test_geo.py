"""LocalFrame: the meridian convergence and true ↔ grid bearings, checked numerically."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from pyproj import Geod, Proj

from colregs9_cli.geo import LocalFrame

FRAME = LocalFrame(56.0, 11.0)
GEOD = Geod(ellps="WGS84")


def grid_bearing_deg(frame: LocalFrame, lat: float, lon: float, true_deg: float) -> float:
    """Grid bearing of a 10 m geodesic leaving (lat, lon) at ``true_deg``, measured in the frame."""
    end_lon, end_lat, _ = GEOD.fwd(lon, lat, true_deg, 10.0)
    north, east = frame.to_local([lat, end_lat], [lon, end_lon])
    return float(np.degrees(np.arctan2(east[1] - east[0], north[1] - north[0])))


@pytest.mark.parametrize("lon", [7.0, 9.0, 10.5, 11.0, 11.5, 13.0, 15.5])
@pytest.mark.parametrize("lat", [54.5, 56.0, 57.8])
@pytest.mark.parametrize("true_deg", [0.0, 45.0, 200.0])
def test_grid_bearing_is_true_minus_convergence(lat: float, lon: float, true_deg: float) -> None:
    convergence_deg = float(FRAME.grid_convergence_deg(lat, lon))
    measured = grid_bearing_deg(FRAME, lat, lon, true_deg)
    assert (measured - (true_deg - convergence_deg) + 180.0) % 360.0 - 180.0 == pytest.approx(
        0.0, abs=1e-4
    )
    assert float(FRAME.true_to_grid_deg(true_deg, lat, lon)) == pytest.approx(
        (true_deg - convergence_deg) % 360.0, abs=1e-12
    )


def test_convergence_is_zero_on_the_central_meridian_and_changes_sign_across_it() -> None:
    lat = np.array([54.5, 56.0, 57.8])
    assert FRAME.grid_convergence_deg(lat, np.full(3, 11.0)) == pytest.approx(0.0, abs=1e-12)
    east = FRAME.grid_convergence_deg(lat, np.full(3, 13.0))
    west = FRAME.grid_convergence_deg(lat, np.full(3, 9.0))
    assert (east > 0.0).all() and (west < 0.0).all()
    assert east == pytest.approx(-west, rel=1e-9)


@pytest.mark.parametrize("d_lon", [-3.0, -1.0, 0.5, 2.0, 4.0])
@pytest.mark.parametrize("lat", [54.5, 56.0, 57.8])
def test_convergence_is_about_delta_lon_times_sin_lat(d_lon: float, lat: float) -> None:
    # The leading term of the series (Snyder 1987, eq. 8-15 with the second term < 0.3 % here).
    approximation = d_lon * np.sin(np.radians(lat))
    assert float(FRAME.grid_convergence_deg(lat, 11.0 + d_lon)) == pytest.approx(
        approximation, rel=3e-3
    )


def test_danish_edges_reach_about_two_degrees() -> None:
    # The national frame is centred near 11° E; Bornholm (15° E) and the North Sea coast
    # (8° E) lie 2.5°–4° of longitude away.
    assert abs(float(FRAME.grid_convergence_deg(55.1, 15.0))) == pytest.approx(3.28, abs=0.01)
    assert abs(float(FRAME.grid_convergence_deg(56.0, 8.1))) == pytest.approx(2.40, abs=0.01)


def test_bearings_wrap_and_round_trip() -> None:
    lat, lon = np.array([56.5, 56.5, 55.0]), np.array([13.0, 9.0, 12.0])
    true_deg = np.array([1.0, 359.0, 180.0])
    grid = FRAME.true_to_grid_deg(true_deg, lat, lon)
    assert ((grid >= 0.0) & (grid < 360.0)).all()
    assert grid[0] == pytest.approx(360.0 + 1.0 - 1.668, abs=1e-3)  # east: crosses north
    assert grid[1] == pytest.approx(359.0 + 1.668 - 360.0, abs=1e-3)  # west: crosses north
    assert FRAME.grid_to_true_deg(grid, lat, lon) == pytest.approx(true_deg, abs=1e-9)


def test_unknown_positions_and_bearings_stay_unknown() -> None:
    convergence = FRAME.grid_convergence_deg([56.0, np.nan, 56.0], [13.0, 12.0, np.nan])
    assert np.isfinite(convergence[0]) and np.isnan(convergence[1:]).all()
    assert np.isnan(FRAME.true_to_grid_deg(np.nan, 56.0, 13.0))
    assert FRAME.grid_convergence_deg([], []).shape == (0,)
    assert FRAME.grid_convergence_deg(56.0, [9.0, 13.0]).shape == (2,)


@pytest.mark.parametrize("lat0", [0.0, 56.0, 78.0, -45.0])
def test_convergence_series_agrees_with_proj_everywhere(lat0: float) -> None:
    """The closed-form series near the central meridian and PROJ's get_factors beyond it
    give the same convergence, across the antimeridian too."""
    frame = LocalFrame(lat0, 175.0)
    lat, lon = np.meshgrid(np.linspace(-85.0, 85.0, 35), np.linspace(150.0, 200.0, 101))
    lon = (lon.ravel() + 180.0) % 360.0 - 180.0
    lat = lat.ravel()
    got = frame.grid_convergence_deg(lat, lon)
    factors = Proj(frame.crs).get_factors(lon, lat)
    expected = np.asarray(factors.meridian_convergence, dtype=float)
    assert np.abs(got - expected).max() < 2e-5
    assert np.isnan(frame.grid_convergence_deg(np.nan, 10.0))


@pytest.mark.parametrize(
    ("lon_min", "lon_max", "centre"),
    [(10.0, 20.0, 15.0), (-180.0, 180.0, -180.0), (170.0, -170.0, -180.0), (-10.0, 10.0, 0.0)],
)
def test_a_box_split_at_the_antimeridian_is_centred_on_it(
    lon_min: float, lon_max: float, centre: float
) -> None:
    assert LocalFrame.centred_on(-17.1, -16.9, lon_min, lon_max).lon0_deg == centre


def test_shapes_across_the_antimeridian_are_cut_there_in_wgs84() -> None:
    frame = LocalFrame(-17.0, 180.0)
    north_m, east_m = frame.to_local(
        [-17.05, -17.05, -16.95, -16.95], [179.9, -179.9, -179.9, 179.9]
    )
    across = shapely.Polygon(np.column_stack([east_m, north_m]))
    near = shapely.Point(*frame.to_local([-17.0], [179.95])[::-1])
    cut, point = frame.shapes_to_wgs84([across, near])
    assert cut.is_valid and cut.geom_type == "MultiPolygon" and len(cut.geoms) == 2
    assert cut.area == pytest.approx(0.02, rel=1e-3)  # 0.2° by 0.1°, not round the globe
    assert sorted(round(g.bounds[0], 6) for g in cut.geoms) == [-180.0, 179.9]
    assert point.x == pytest.approx(179.95)


def test_a_vessel_at_rest_without_a_course_has_no_velocity() -> None:
    from colregs9_cli.geo import velocity_ecef_mps, velocity_mps

    at_rest = velocity_ecef_mps([57.0, 57.0], [10.0, 10.0], [0.0, 2.0], [np.nan, np.nan])
    assert np.array_equal(at_rest[0], np.zeros(3))
    assert np.isnan(at_rest[1]).all()  # moving with no course: unknown
    north, east = velocity_mps([0.0, 1.0], [np.nan, 90.0])
    assert (north[0], east[0]) == (0.0, 0.0) and east[1] == pytest.approx(1.0)


def test_shapes_away_from_180_convert_exactly() -> None:
    frame = LocalFrame(32.7, -117.2)
    north_m, east_m = frame.to_local([32.6, 32.8], [-117.3, -117.1])
    (line,) = frame.shapes_to_wgs84([shapely.LineString(np.column_stack([east_m, north_m]))])
    lat_deg, lon_deg = frame.to_geodetic(north_m, east_m)
    assert np.array_equal(shapely.get_coordinates(line), np.column_stack([lon_deg, lat_deg]))
