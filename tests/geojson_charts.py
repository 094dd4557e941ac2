"""Charts written as GeoJSON in a local frame's metres, for tests that need depth areas and
channels of a shape they choose (GDAL reads them as it reads S-57 cells' layers)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import shapely

from colregs9_cli.geo import LocalFrame


def feature(frame: LocalFrame, properties: dict[str, Any], geometry: Any) -> dict[str, Any]:
    """One GeoJSON feature of ``geometry`` given in ``frame``'s metres (x east, y north)."""
    (wgs84,) = frame.shapes_to_wgs84([geometry])
    return {
        "type": "Feature",
        "properties": properties,
        "geometry": json.loads(shapely.to_geojson(wgs84)),
    }


def write_chart(
    path: Path,
    frame: LocalFrame,
    *features: tuple[dict[str, Any], Any],
    box_m: float = 3000.0,
    **detail: Any,
) -> Path:
    """A chart covering a square of ``box_m`` either side of the frame's origin (``M_COVR``
    with ``detail``), with ``features`` (properties, geometry) and, where none is given, one
    depth area of 30 m over it all."""
    square = shapely.box(-box_m, -box_m, box_m, box_m)
    collection = [
        feature(frame, {"OBJL": "M_COVR", "CATCOV": 1, **detail}, square),
        *(feature(frame, p, g) for p, g in features),
    ]
    if not any(p.get("OBJL") == "DEPARE" for p, _ in features):
        collection.append(feature(frame, {"OBJL": "DEPARE", "DRVAL1": 30.0}, square))
    path.write_text(json.dumps({"type": "FeatureCollection", "features": collection}))
    return path
