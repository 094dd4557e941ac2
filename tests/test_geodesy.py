"""Ranges and CPAs agree with a geodesic computation (pyproj ``Geod``) anywhere on Earth.

Two vessels sail geodesics laid with ``Geod.fwd`` so that they cross, report every 2 s with
the geodesic's azimuth as COG, and go through tracks and the pair search with a map frame
centred far from them (as a national or satellite feed's frame is). At the trigger, the
range must agree with ``Geod.inv`` between the two reported positions, and the CPA with the
least geodesic distance between the two vessels sailing on, to 1 m + 0.2 %.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely
from pyproj import Geod

from colregs9_cli.core.encounters import find_encounters
from colregs9_cli.core.tracks import build_tracks
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.replay_params import ReplayParams

GEOD = Geod(ellps="WGS84")
T0 = pd.Timestamp("2024-01-01T00:00:00Z")
SPEED_MPS = 6.0
PARAMS = ReplayParams()


def _at(lat: float, lon: float, azimuth: float, seconds: np.ndarray):
    """Position and course (the geodesic's azimuth there) after ``seconds`` of sailing."""
    n = len(seconds)
    lons, lats, back = GEOD.fwd(
        np.full(n, lon), np.full(n, lat), np.full(n, azimuth), SPEED_MPS * seconds
    )
    lons = ((np.asarray(lons) + 180.0) % 360.0) - 180.0
    return np.asarray(lats), lons, (np.asarray(back) + 180.0) % 360.0


def _reports(mmsi: int, start: tuple[float, float, float], seconds: np.ndarray):
    lat, lon, course = _at(*start, seconds)
    return pd.DataFrame(
        {
            "timestamp": T0 + pd.to_timedelta(seconds, unit="s"),
            "mmsi": mmsi,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": SPEED_MPS * 3600.0 / 1852.0,
            "cog_deg": course,
            "heading_deg": np.nan,
            "nav_status": 0.0,
        }
    )


def crossing_at(lat: float, lon: float, miss_m: float = 60.0):
    """Own ship north-east-bound through (lat, lon) at t = 600 s; the target crosses her
    track from her starboard side, passing ``miss_m`` ahead of that point. Returns each
    vessel's start (lat, lon, azimuth)."""
    own_lon, own_lat, _ = GEOD.fwd(lon, lat, 225.0, SPEED_MPS * 600.0)
    mid_lon, mid_lat, _ = GEOD.fwd(lon, lat, 45.0, miss_m)
    tgt_lon, tgt_lat, _ = GEOD.fwd(mid_lon, mid_lat, 135.0, SPEED_MPS * 600.0)
    return (own_lat, own_lon, 45.0), (tgt_lat, tgt_lon, 315.0)


def _geodesic_truth(own_start, target_start, trigger_s: float) -> tuple[float, float]:
    """Range at the trigger, and the least distance as both sail on (0.1 s steps)."""
    seconds = trigger_s + np.arange(0.0, 400.0, 0.1)
    o_lat, o_lon, _ = _at(*own_start, seconds)
    t_lat, t_lon, _ = _at(*target_start, seconds)
    _, _, apart = GEOD.inv(o_lon, o_lat, t_lon, t_lat)
    return float(apart[0]), float(np.min(apart))


PLACES = [
    (57.05, 9.95, LocalFrame(57.05, 9.95)),  # the frame's centre
    (57.0, 15.0, LocalFrame(56.0, 11.0)),  # 240 km from a Danish national frame's centre
    (55.0, 3.5, LocalFrame(56.0, 11.0)),  # 480 km off it
    (78.2, 15.6, LocalFrame(70.0, 20.0)),  # Svalbard in a northern frame
    (0.0, 179.995, LocalFrame(0.0, 179.0)),  # across the antimeridian
    (-45.0, -179.998, LocalFrame(-45.0, 178.0)),
    (-33.9, 151.3, LocalFrame(-25.0, 135.0)),  # a satellite feed's frame over Australia
]


@pytest.mark.parametrize(("lat", "lon", "frame"), PLACES)
def test_range_and_cpa_agree_with_geod(lat: float, lon: float, frame: LocalFrame) -> None:
    own_start, target_start = crossing_at(lat, lon)
    seconds = np.arange(0.0, 1201.0, 2.0)
    reports = pd.concat(
        [_reports(1, own_start, seconds), _reports(2, target_start, seconds)], ignore_index=True
    )
    tracks = build_tracks(reports, frame, PARAMS.tracks)
    (encounter,) = find_encounters(tracks, PARAMS.encounters, own_mmsi=[1]).triggered
    assert encounter.range_m_at_trigger is not None and encounter.cpa_m_at_trigger is not None
    assert encounter.trigger is not None
    trigger_s = (encounter.trigger - T0).total_seconds()
    range_m, cpa_m = _geodesic_truth(own_start, target_start, trigger_s)
    assert encounter.range_m_at_trigger == pytest.approx(range_m, abs=1.0 + 0.002 * range_m)
    assert encounter.cpa_m_at_trigger == pytest.approx(cpa_m, abs=1.0 + 0.002 * cpa_m)
    assert 40.0 < cpa_m < 80.0  # the geometry is what it was built to be


def _marinecadastre_rows(mmsi: int, start: tuple[float, float, float]) -> pd.DataFrame:
    seconds = np.arange(0.0, 1201.0, 2.0)
    lat, lon, course = _at(*start, seconds)
    return pd.DataFrame(
        {
            "MMSI": mmsi,
            "BaseDateTime": (T0 + pd.to_timedelta(seconds, unit="s")).strftime("%Y-%m-%dT%H:%M:%S"),
            "LAT": lat.round(7),
            "LON": lon.round(7),
            "SOG": round(SPEED_MPS * 3600.0 / 1852.0, 1),
            "COG": course.round(1),
            "Heading": 511,
            "VesselName": f"V{mmsi}",
            "IMO": "",
            "CallSign": "",
            "VesselType": 70,
            "Status": 0,
            "Length": 100,
            "Width": 20,
            "Draft": 5,
            "Cargo": 70,
            "TransceiverClass": "A",
        }
    )


def test_a_replay_over_the_whole_earth_keeps_every_pair(tmp_path) -> None:
    # A satellite feed's pairs: one on the equator across the antimeridian, one off Denmark.
    # The run's frame, centred on the data (28.5° N, 95° E), reaches neither: each pair keeps
    # its exact geometry, is estimated "unknown", and is drawn and mapped in a frame of its
    # own (before, PROJ's inf positions lost the far pair or stopped the run).
    places = {(366000001, 366000002): (0.0, 179.999), (366000003, 366000004): (57.0, 10.0)}
    rows = []
    for (own, target), (lat, lon) in places.items():
        own_start, target_start = crossing_at(lat, lon)
        rows += [_marinecadastre_rows(own, own_start), _marinecadastre_rows(target, target_start)]
    path = tmp_path / "world.csv"
    pd.concat(rows).to_csv(path, index=False)
    result = run_replay([path], out_dir=tmp_path / "report", quiet=True)
    assert {(p.summary.mmsi_a, p.summary.mmsi_b) for p in result.pairs} == set(places)
    for pair in result.pairs:
        lat, lon = places[(pair.summary.mmsi_a, pair.summary.mmsi_b)]
        for seat in pair.seats:
            assert not seat.in_run_frame
            assert seat.frame.within_reach(lat, lon)
            assert seat.summary.target_estimated_restricted == "unknown"
            assert (result.out_dir / "encounters" / f"{seat.summary.encounter_id}.png").is_file()
            own_start, target_start = crossing_at(lat, lon)
            if seat.summary.own_mmsi != pair.summary.mmsi_a:
                own_start, target_start = target_start, own_start
            trigger_s = (seat.summary.trigger_utc - T0).total_seconds()
            range_m, cpa_m = _geodesic_truth(own_start, target_start, trigger_s)
            assert seat.summary.range_m_at_trigger == pytest.approx(range_m, abs=1.0, rel=2e-3)
            assert seat.summary.cpa_m == pytest.approx(cpa_m, abs=1.0, rel=2e-3)
    # The report's points lie where the vessels were, on either side of 180°.
    _, _, wkb, fields = pyogrio.raw.read(result.out_dir / "report.gpkg", layer="encounters")
    points = shapely.from_wkb(wkb)
    names = list(pyogrio.read_info(result.out_dir / "report.gpkg", layer="encounters")["fields"])
    own_mmsi = fields[names.index("own_mmsi")]
    for point, mmsi in zip(points[::2], own_mmsi[::2], strict=True):
        key = next(k for k in places if int(mmsi) in k)
        lat, lon = places[key]
        _, _, apart = GEOD.inv(lon, lat, point.x, point.y)
        assert apart < 3_000.0
