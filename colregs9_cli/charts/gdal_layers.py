"""GDAL through pyogrio: the layers of a chart file, read quietly, with errors naming the file.

The reader (``read``) lists and reads the layers of every chart file (S-57 cell, GeoJSON,
GeoPackage) here, an S-57 cell with the S57 driver's open options ``S57_OPEN_OPTIONS``
(``read`` says which and why), which the cell checks (``cells``) use for its DSID record too.
GDAL's warnings are kept off stderr (``gdal_quiet``), and what it cannot read is one
``ChartError`` that names the file, and the layer and feature where it can.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pyogrio
import shapely
from numpy.typing import NDArray
from pyogrio.errors import DataLayerError, DataSourceError, FieldError, GeometryError

from ..errors import ChartError

S57_OPEN_OPTIONS = {"UPDATES": "APPLY", "SPLIT_MULTIPOINT": "ON", "ADD_SOUNDG_DEPTH": "ON"}


@contextmanager
def gdal_quiet() -> Iterator[None]:
    """GDAL's warnings (pyogrio passes them on as ``RuntimeWarning``) kept off stderr: a file
    GDAL cannot read is one ``ChartError``, and what it can read needs no remark."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def read_layer(path: Path, layer: str | int, **options: str) -> tuple[dict[str, Any], Any]:
    """One layer's CRS and attribute columns, and its geometries; a ``ChartError`` names it."""
    try:
        with gdal_quiet():  # and shapely's about NaN vertices: _check_finite names them
            meta, _, wkb, field_data = pyogrio.raw.read(path, layer=layer, **options)
            geometries = shapely.from_wkb(wkb) if wkb is not None else np.empty(0, dtype=object)
    except (
        DataSourceError,
        DataLayerError,
        FieldError,
        GeometryError,
        RuntimeError,
        shapely.errors.GEOSException,
    ) as exc:
        raise ChartError(
            f"{path}: cannot read layer {layer} ({first_line(exc)}); give an S-57 .000, "
            "GeoJSON or GeoPackage chart"
        ) from None
    columns = dict(zip(meta["fields"], field_data, strict=True))
    _check_finite(geometries, path, layer, columns)
    return {"crs": meta.get("crs"), "columns": columns}, geometries


def _check_finite(
    geometries: NDArray[np.object_], path: Path, layer: str | int, columns: Mapping[str, Any]
) -> None:
    """A vertex that is not a finite number (NaN, inf) is an error naming the feature: GEOS
    cannot build or repair such a geometry."""
    if len(geometries) == 0:
        return
    coordinates, owner = shapely.get_coordinates(geometries, return_index=True)
    bad = ~np.isfinite(coordinates).all(axis=1)
    if not bad.any():
        return
    feature = int(owner[bad][0])
    objl = columns.get("OBJL")
    kind = f" ({objl[feature]})" if objl is not None and objl[feature] is not None else ""
    x, y = coordinates[bad][0]
    raise ChartError(
        f"{path}: layer {layer}, feature {feature + 1}{kind}: the vertex ({x}, {y}) is not a "
        "finite number; fix or remove that feature"
    )


def first_line(exc: BaseException) -> str:
    """The first line of an exception's message (GDAL's run to several), for an error,
    without GDAL's hint to prefix the path with a driver's name, which colregs9 does not
    take."""
    text = str(exc).strip()
    if not text:
        return type(exc).__name__
    line = text.splitlines()[0]
    return line.split("; It might help to specify the correct driver", 1)[0].rstrip(" .;")


def list_layers(path: Path) -> list[str]:
    """The names of a chart file's layers; a ``ChartError`` where GDAL cannot open it."""
    try:
        with gdal_quiet():
            return [str(name) for name, _ in pyogrio.list_layers(path)]
    except (DataSourceError, DataLayerError, RuntimeError) as exc:
        raise ChartError(
            f"{path}: not a chart GDAL can open ({first_line(exc)}); give an S-57 .000, "
            "GeoJSON or GeoPackage chart"
        ) from None
