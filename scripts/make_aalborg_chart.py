"""Generate the MODELLED Aalborg chart ``colregs9_cli/data/demo/aalborg_modelled.geojson``.

The land comes from the real coastline (``fixtures/charts/aalborg_coastline.geojson``,
DTUAqua/limfjord). Every depth in the output is INVENTED: no public Danish ENC or depth
survey of Limfjorden at Aalborg exists. The chart is modelled, not surveyed, and not for
navigation; it exists so that the paper's Greenhopper case study can be replayed.

How it is built (all distances in the local transverse Mercator frame centred on the
paper's region R, ``colregs9_cli.geo.LocalFrame``):

1. Land and water. The coastline lines are clipped to the chart box (lon 9.85–9.998,
   lat 57.02–57.09; the source stops just short of 10.0°E), noded together with the box's
   edges and polygonized. The face that contains ``WATER_SEED`` (mid-fjord between
   Aalborg and Nørresundby, inside region R) is the fjord; every other face is land
   (LNDARE). The two closed rings that cross the fjord at 9.91°E and 9.92°E are the
   railway bridge and Limfjordsbroen: they span the water and are left out, so the water
   under them stays water.
2. Depth bands from the distance ``d`` to land: 0–2 m for ``d < 15 m``, 2–4 m for
   ``15 <= d < 35 m``, 4–6 m beyond. Limfjorden is a shallow fjord; most of it is
   modelled as 4–6 m. Its banks at Aalborg and Nørresundby are largely quays and
   dredged, so the 4 m line is modelled close in; a vessel drawing less than 4 m (the
   paper's mean draught, 3.2 m) has the fjord but for a 35 m margin.
3. A natural deep basin, 6–12 m, only where the fjord is wide: the points within
   ``BASIN_REACH_M`` of the water that is at least ``BASIN_CORE_M`` from land (so it
   reaches to 100 m off the shore). Where the fjord is narrower than ``2 * BASIN_CORE_M``
   (the bridges and the stretch east of them) there is no basin, so a vessel that needs
   more than 4 m of water (DRVAL1 >= 5 m for a 5 m draught) is confined to the fairway
   there; where the fjord widens (the arm north-east of region R, and west of the
   bridges towards Egholm) the basin gives room to manoeuvre.
4. A dredged fairway (DRGARE, 8 m) of width ``2 * FAIRWAY_HALF_WIDTH_M`` along the
   hand-drawn centreline ``FAIRWAY_CENTRELINE`` (lon, lat), which follows the middle of
   the fjord through the bridges, north of Egholm in the west. It is kept at least
   ``FAIRWAY_OFF_LAND_M`` off the land.
5. The depth areas partition the water: the fairway first, then the basin minus the
   fairway, then each band minus both. Geometry is simplified to ``SIMPLIFY_M``.
6. An exact partition in lon/lat. Transforming each area to lon/lat and rounding it on
   its own would leave millimetre gaps and overlaps between neighbours (an edge that one
   area has as one segment and its neighbour as two does not stay straight under the
   projection), and those gaps would punch holes into the navigable water. So the
   boundaries of all areas and of the chart box are transformed, snapped ONCE to a
   ``GRID_DEG`` grid (about 1 cm) and noded together, and polygonized into faces; every
   face takes the attributes of the area it lies in (a face left in a sliver between two
   areas joins the nearest one; a face outside the water is land), and each area is
   the union of its faces. Neighbours therefore share their edges vertex for vertex, the
   file is byte-for-byte reproducible, and ``tests/test_aalborg_chart.py`` checks that the
   areas neither overlap nor leave holes.

Run: ``python scripts/make_aalborg_chart.py [OUT.geojson]``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from shapely.geometry import LineString, MultiPolygon, Point, Polygon, box, mapping, shape
from shapely.geometry.base import BaseGeometry
from shapely.ops import polygonize, unary_union

from colregs9_cli.geo import LocalFrame

ROOT = Path(__file__).resolve().parents[1]
COASTLINE = ROOT / "fixtures" / "charts" / "aalborg_coastline.geojson"
DEFAULT_OUT = ROOT / "colregs9_cli" / "data" / "demo" / "aalborg_modelled.geojson"

SOURCE_NOTE = "MODELLED - not surveyed, not for navigation"
REGION_R = {"lat_min": 57.044196, "lat_max": 57.062865, "lon_min": 9.909933, "lon_max": 9.971545}
CHART_BOX = (9.85, 57.02, 9.998, 57.09)  # lon_min, lat_min, lon_max, lat_max
WATER_SEED = (9.925, 57.0535)  # lon, lat: mid-fjord just east of Limfjordsbroen
BRIDGE_FEATURES = (1, 2)  # indices of the bridge rings in the coastline file

# (near_m, far_m, DRVAL1, DRVAL2): distance from land → depth band
BAND_LIMITS_M = ((0.0, 15.0, 0.0, 2.0), (15.0, 35.0, 2.0, 4.0), (35.0, None, 4.0, 6.0))
BASIN_CORE_M = 300.0
BASIN_REACH_M = 200.0
BASIN_DEPTH_M = (6.0, 12.0)
FAIRWAY_HALF_WIDTH_M = 60.0
FAIRWAY_DEPTH_M = (8.0, 10.0)
FAIRWAY_OFF_LAND_M = 40.0
SIMPLIFY_M = 2.0
GRID_DEG = 1e-7  # ~0.6 cm east, 1.1 cm north at 57°N
DECIMALS = 7

# lon, lat: the middle of the fjord from the west edge (north of Egholm) to the east edge
FAIRWAY_CENTRELINE = (
    (9.850, 57.0790),
    (9.862, 57.0752),
    (9.8705, 57.0690),
    (9.8788, 57.0654),
    (9.8870, 57.0625),
    (9.8953, 57.0616),
    (9.9035, 57.0606),
    (9.9076, 57.0594),
    (9.9118, 57.0578),
    (9.9159, 57.0561),
    (9.9200, 57.0546),
    (9.9241, 57.0532),
    (9.9283, 57.0522),
    (9.9324, 57.0514),
    (9.9365, 57.0512),
    (9.9406, 57.0518),
    (9.9447, 57.0532),
    (9.9488, 57.0543),
    (9.9530, 57.0554),
    (9.9571, 57.0566),
    (9.9605, 57.0595),
    (9.9640, 57.0640),
    (9.9680, 57.0685),
    (9.9736, 57.0732),
    (9.9777, 57.0760),
    (9.9818, 57.0782),
    (9.9860, 57.0800),
    (9.9901, 57.0815),
    (9.998, 57.0835),
)


def chart_frame() -> LocalFrame:
    return LocalFrame.centred_on(
        REGION_R["lat_min"], REGION_R["lat_max"], REGION_R["lon_min"], REGION_R["lon_max"]
    )


def _to_metric(geom: BaseGeometry, frame: LocalFrame) -> BaseGeometry:
    def project(lon_lat: np.ndarray) -> np.ndarray:
        north_m, east_m = frame.to_local(lon_lat[:, 1], lon_lat[:, 0])
        return np.column_stack([east_m, north_m])

    return shapely.transform(geom, project)


def _to_lon_lat(geom: BaseGeometry, frame: LocalFrame) -> BaseGeometry:
    def unproject(east_north: np.ndarray) -> np.ndarray:
        lat_deg, lon_deg = frame.to_geodetic(east_north[:, 1], east_north[:, 0])
        return np.column_stack([lon_deg, lat_deg])

    return shapely.transform(geom, unproject)


def _partition(
    areas_ll: list[BaseGeometry], water_ll: BaseGeometry
) -> tuple[list[MultiPolygon], MultiPolygon]:
    """The areas and the land as an exact partition of the chart box on the ``GRID_DEG``
    grid: one noding of every boundary, polygonized, each face given to one area or to land.
    """
    chart_box = box(*CHART_BOX)
    linework = shapely.union_all(
        [*(shapely.boundary(area) for area in areas_ll), chart_box.exterior], grid_size=GRID_DEG
    )
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(linework)))
    points = shapely.point_on_surface(faces)
    inside = shapely.contains(chart_box, points)
    faces, points = faces[inside], points[inside]
    tree = shapely.STRtree(areas_ll)
    # the first area holding the face: areas come in priority order, and where two
    # overlap it is by a rounding sliver
    land = len(areas_ll)
    owner = np.full(len(faces), land)
    face_index, area_index = tree.query(points, predicate="within")
    np.minimum.at(owner, face_index, area_index)
    gaps = np.flatnonzero((owner == land) & shapely.contains(water_ll, points))
    gap_index, nearest_area = tree.query_nearest(points[gaps], all_matches=False)
    owner[gaps[gap_index]] = nearest_area
    geometries = [_union(faces[owner == index]) for index in range(len(areas_ll))]
    return geometries, _union(faces[owner == land])


def _union(faces: np.ndarray) -> MultiPolygon:
    merged = shapely.union_all(faces, grid_size=GRID_DEG)
    parts = [part for part in shapely.get_parts(merged) if isinstance(part, Polygon)]
    return MultiPolygon(parts)


def water_polygon(coastline: dict[str, Any]) -> Polygon:
    """The fjord (lon/lat): the polygonized face of coastline + chart box holding the seed."""
    chart_box = box(*CHART_BOX)
    lines = [
        shape(feature["geometry"]).intersection(chart_box)
        for index, feature in enumerate(coastline["features"])
        if index not in BRIDGE_FEATURES
    ]
    faces = list(polygonize(unary_union([*lines, chart_box.exterior])))
    seed = Point(WATER_SEED)
    water = [face for face in faces if face.contains(seed)]
    if len(water) != 1:
        raise RuntimeError(f"expected one water face at {WATER_SEED}, found {len(water)}")
    return water[0]


def build_chart(coastline: dict[str, Any]) -> dict[str, Any]:
    """The modelled chart as a GeoJSON FeatureCollection (lon/lat)."""
    frame = chart_frame()
    water_ll = water_polygon(coastline)
    water_m = _to_metric(water_ll, frame).simplify(SIMPLIFY_M).buffer(0.0)
    # the land inside the chart box: the fjord's open ends at the box edges are not shores
    land_m = _to_metric(box(*CHART_BOX), frame).difference(water_m)
    centreline_m = _to_metric(LineString(FAIRWAY_CENTRELINE), frame)

    def off_land(distance_m: float) -> BaseGeometry:
        """The water at least ``distance_m`` from land, simplified once here only, so that
        the differences below share their edges exactly."""
        return water_m.difference(land_m.buffer(distance_m)).simplify(SIMPLIFY_M)

    fairway = (
        centreline_m.buffer(FAIRWAY_HALF_WIDTH_M)
        .simplify(SIMPLIFY_M)
        .intersection(off_land(FAIRWAY_OFF_LAND_M))
    )
    basin_outline = off_land(BASIN_CORE_M).buffer(BASIN_REACH_M).simplify(SIMPLIFY_M)
    basin = basin_outline.intersection(water_m).difference(fairway)
    taken = unary_union([fairway, basin])
    areas: list[tuple[str, float, float, BaseGeometry]] = [
        ("DRGARE", *FAIRWAY_DEPTH_M, fairway),
        ("DEPARE", *BASIN_DEPTH_M, basin),
    ]
    # deepest band first: each band is what is left at least ``near_m`` off the land
    for near_m, _far_m, drval1, drval2 in reversed(BAND_LIMITS_M):
        band = (off_land(near_m) if near_m > 0.0 else water_m).difference(taken)
        taken = unary_union([taken, band])
        areas.append(("DEPARE", drval1, drval2, band))

    geometries_ll, land_ll = _partition(
        [_to_lon_lat(geom_m, frame) for *_, geom_m in areas], _to_lon_lat(water_m, frame)
    )
    features = [_feature("LNDARE", None, None, land_ll)]
    for (objl, drval1, drval2, _), geom_ll in zip(areas, geometries_ll, strict=True):
        features.append(_feature(objl, drval1, drval2, geom_ll))
    return {
        "type": "FeatureCollection",
        "name": "aalborg_modelled",
        "metadata": {
            "modelled": True,
            "surveyed": False,
            "note": (
                "Modelled chart of Limfjorden at Aalborg. Land from the real coastline "
                "(DTUAqua/limfjord); every depth is invented for the paper's case study. "
                "Not surveyed, not for navigation."
            ),
            "generator": "scripts/make_aalborg_chart.py",
            "depth_units": "metres",
            "region_r": REGION_R,
        },
        "features": features,
    }


def _feature(
    objl: str, drval1: float | None, drval2: float | None, geom: BaseGeometry
) -> dict[str, Any]:
    return {
        "type": "Feature",
        "properties": {
            "OBJL": objl,
            "DRVAL1": drval1,
            "DRVAL2": drval2,
            "source": SOURCE_NOTE,
        },
        "geometry": _rounded(mapping(geom)),
    }


def _rounded(value: Any) -> Any:
    if isinstance(value, float):
        return round(value, DECIMALS)
    if isinstance(value, list | tuple):
        return [_rounded(item) for item in value]
    if isinstance(value, dict):
        return {key: _rounded(item) for key, item in value.items()}
    return value


def write_chart(out: Path) -> None:
    coastline = json.loads(COASTLINE.read_text(encoding="utf-8"))
    chart = build_chart(coastline)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(chart, separators=(",", ":")) + "\n", encoding="utf-8")


if __name__ == "__main__":
    write_chart(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT_OUT)
