"""Charts written as GeoJSON in a local frame's metres, for tests that need depth areas and
channels of a shape they choose (GDAL reads them as it reads S-57 cells' layers), and the
shapes of such channels."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
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


def annulus_sector(inner_m: float, outer_m: float, to_deg: float) -> Any:
    """A channel bending round the origin: the annulus sector from north clockwise to
    ``to_deg`` (x east, y north)."""
    angles = np.radians(np.linspace(0.0, to_deg, 91))
    outer = np.column_stack([outer_m * np.sin(angles), outer_m * np.cos(angles)])
    inner = np.column_stack([inner_m * np.sin(angles), inner_m * np.cos(angles)])[::-1]
    return shapely.Polygon(np.concatenate([outer, inner]))
