"""Reading a chart file's routeing objects (``s57_classes.CHANNEL_CLASSES``) in WGS84.

An S-57 cell is read through GDAL's S57 driver with the reader's open options (updates
applied, ``read``), one layer per object class. A GeoJSON or GeoPackage chart carries them
as it carries depth areas: features whose ``OBJL`` is the class (``"FAIRWY"``, ``"TSSLPT"``,
or the numeric S-57 code such as 51), or a layer named after the class; with the S-57
attribute names ``OBJNAM``, ``ORIENT``, ``TRAFIC``, ``DRVAL1``, ``DRVAL2``, ``CATTRK``,
``CATNAV``.

A feature's record id is its S-57 feature object identifier as GDAL's S57 driver gives it in
``LNAM`` (16 hex digits: agency, FIDN, FIDS; the same in every edition and update of the
cell), else ``RCID <n>`` (the record's number in the cell), else, for a GeoJSON/GeoPackage
feature with neither, ``<layer>#<n>`` (its number in the layer, from 1).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from ..errors import ChartError
from .gdal_layers import S57_OPEN_OPTIONS, list_layers, read_layer
from .read import S57_SUFFIXES, to_wgs84
from .s57_classes import CHANNEL_CLASS_BY_CODE, CHANNEL_CLASSES

# S-57 attributes read as numbers: (column, what it is, for the error message).
_NUMERIC = (
    ("ORIENT", "an orientation in degrees"),
    ("DRVAL1", "a depth in metres"),
    ("DRVAL2", "a depth in metres"),
    ("TRAFIC", "a traffic flow code (1 inbound, 2 outbound, 3 one-way, 4 two-way)"),
    ("CATTRK", "a category of recommended track (1, 2)"),
    ("CATNAV", "a category of navigation line (1, 2, 3)"),
)


@dataclass(frozen=True)
class ChannelFeatures:
    """One file's routeing objects in WGS84 (x lon, y lat), before projection."""

    path: Path
    geometries: NDArray[np.object_]
    object_class: NDArray[np.object_]  # the S-57 acronym
    record_id: NDArray[np.object_]
    name: NDArray[np.object_]  # OBJNAM, None where not charted
    numbers: Mapping[str, NDArray[np.float64]]  # _NUMERIC's columns, NaN where not charted


def read_channel_features(path: Path) -> ChannelFeatures:
    """The routeing objects of one chart file; a ``ChartError`` names the file, layer and
    value that cannot be read."""
    path = Path(path)
    s57 = path.suffix.lower() in S57_SUFFIXES
    parts = []
    for layer in list_layers(path):
        if s57 and layer not in CHANNEL_CLASSES:
            continue
        if not s57 and layer.upper() == "DSID":
            continue
        meta, geometries = read_layer(path, layer, **(S57_OPEN_OPTIONS if s57 else {}))
        classes = _classes(layer, meta["columns"], len(geometries))
        if not (classes != None).any():  # noqa: E711
            continue
        if not s57:
            geometries = to_wgs84(geometries, meta["crs"], path)
        parts.append(_layer_part(path, layer, geometries, classes, meta["columns"]))
    if not parts:
        empty = np.empty(0, dtype=object)
        return ChannelFeatures(
            path, empty, empty, empty, empty, {c: np.empty(0) for c, _ in _NUMERIC}
        )
    return ChannelFeatures(
        path,
        np.concatenate([p.geometries for p in parts]),
        np.concatenate([p.object_class for p in parts]),
        np.concatenate([p.record_id for p in parts]),
        np.concatenate([p.name for p in parts]),
        {c: np.concatenate([p.numbers[c] for p in parts]) for c, _ in _NUMERIC},
    )


def _classes(layer: str, columns: Mapping[str, Any], n: int) -> NDArray[np.object_]:
    """Each feature's routeing class (acronym), None for features of other classes: from
    ``OBJL`` (acronym or numeric code), else from the layer's name."""
    objl = columns.get("OBJL")
    if objl is None:
        name = layer.upper()
        return np.full(n, name if name in CHANNEL_CLASSES else None, dtype=object)
    return np.asarray([_channel_class(v) for v in objl], dtype=object)


def _channel_class(value: Any) -> str | None:
    if value is None:
        return None
    text = str(value).strip().upper()
    if text.isdigit():
        return CHANNEL_CLASS_BY_CODE.get(int(text))
    return text if text in CHANNEL_CLASSES else None


def _layer_part(
    path: Path,
    layer: str,
    geometries: NDArray[np.object_],
    classes: NDArray[np.object_],
    columns: Mapping[str, Any],
) -> ChannelFeatures:
    """The routeing features of one layer, without those GDAL gave no geometry."""
    keep = (classes != None) & ~shapely.is_missing(geometries)  # noqa: E711
    numbers = {
        column: _numbers(columns.get(column), len(geometries), path, layer, column, meaning)
        for column, meaning in _NUMERIC
    }
    names = columns.get("OBJNAM")
    name = np.asarray(
        [_text(v) for v in names] if names is not None else [None] * len(geometries), dtype=object
    )
    return ChannelFeatures(
        path,
        geometries[keep],
        classes[keep],
        _record_ids(layer, columns, len(geometries))[keep],
        name[keep],
        {column: values[keep] for column, values in numbers.items()},
    )


def _text(value: Any) -> str | None:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return None
    text = str(value).strip()
    return text or None


def _numbers(
    values: Any, n: int, path: Path, layer: str, column: str, meaning: str
) -> NDArray[np.float64]:
    if values is None:
        return np.full(n, np.nan)
    out = np.full(n, np.nan)
    for i, value in enumerate(values):
        if _text(value) is None:
            continue
        try:
            out[i] = float(value)
        except (TypeError, ValueError):
            raise ChartError(
                f"{path}: layer {layer}, feature {i + 1}: {column} is {value!r}, which is not "
                f"{meaning}; fix the value or leave it empty"
            ) from None
    return out


def _record_ids(layer: str, columns: Mapping[str, Any], n: int) -> NDArray[np.object_]:
    """LNAM (the S-57 feature object identifier), else ``RCID <n>``, else ``<layer>#<n>``."""
    lnam = columns.get("LNAM")
    rcid = columns.get("RCID")
    ids = []
    for i in range(n):
        foid = _text(lnam[i]) if lnam is not None else None
        record = _text(rcid[i]) if rcid is not None else None
        if foid is not None:
            ids.append(foid)
        elif record is not None:
            ids.append(f"RCID {record}")
        else:
            ids.append(f"{layer}#{i + 1}")
    return np.asarray(ids, dtype=object)
