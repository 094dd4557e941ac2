"""``report.gpkg``: the replay's encounters for QGIS, in WGS84, written with GDAL (pyogrio).

Layers (each only when it has features):

- ``encounters``: a point at each vessel's position at the trigger, one per vessel and
  encounter row, with every ``encounters.csv`` column and ``vessel`` (own or target);
- ``tracks``: each vessel's track over the encounter, a line per vessel and encounter;
- ``cpa``: each vessel's position predicted at TCPA from the trigger;
- ``domains``: the target's ship-domain ellipses at the trigger, with ``restricted`` and
  ``covered`` (booleans), ``state`` (restricted, clear or unknown), ``arc`` and ``step``;
- ``navigable_water``: the water deep enough for each target draught used, where a chart was
  given.

Each layer carries a default QGIS style in the ``layer_styles`` table (``qgis_styles.py``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyogrio
import shapely

from ..chart import Chart
from ..geo import LocalFrame
from ..replay_results import ReplayResult
from .atomic import atomic_path
from .qgis_styles import add_layer_styles

GEOPACKAGE_NAME = "report.gpkg"


def _to_wgs84(frame: LocalFrame, geometries: Any) -> np.ndarray:
    def convert(xy: np.ndarray) -> np.ndarray:
        lat_deg, lon_deg = frame.to_geodetic(xy[:, 1], xy[:, 0])
        return np.column_stack([lon_deg, lat_deg])

    return np.asarray(
        shapely.to_wkb(shapely.transform(np.asarray(geometries, dtype=object), convert)),
        dtype=object,
    )


def _fields(table: pd.DataFrame) -> tuple[list[np.ndarray], list[str]]:
    """Columns as GDAL fields: booleans as booleans, numbers as float, everything else as
    text."""
    values: list[np.ndarray] = []
    names: list[str] = []
    for name in table.columns:
        column = table[name]
        numeric = pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column)
        if pd.api.types.is_bool_dtype(column) and not column.isna().any():
            values.append(column.to_numpy(dtype=bool))
        elif numeric:
            values.append(column.to_numpy(dtype=float, na_value=np.nan))
        else:
            values.append(
                np.asarray([None if pd.isna(v) else str(v) for v in column], dtype=object)
            )
        names.append(str(name))
    return values, names


def write_replay_geopackage(
    path: Path, result: ReplayResult, encounters: pd.DataFrame, chart: Chart | None
) -> Path | None:
    """Write ``report.gpkg`` (see the module docstring); ``encounters`` is encounters.csv as
    written. Returns None when there is nothing to map."""
    outcomes = result.encounters
    if not outcomes:
        return None
    frame = result.frame
    layers: dict[str, tuple[np.ndarray, pd.DataFrame]] = {}
    rows = encounters.reset_index(drop=True)
    points: list[Any] = []
    tracks: list[Any] = []
    cpa: list[Any] = []
    point_rows: list[dict[str, Any]] = []
    track_rows: list[dict[str, Any]] = []
    cpa_rows: list[dict[str, Any]] = []
    for index, outcome in enumerate(outcomes):
        trigger = outcome.series.iloc[0]
        for vessel, track, at_tcpa in (
            ("own", outcome.own_track, outcome.own_at_tcpa_m),
            ("target", outcome.target_track, outcome.target_at_tcpa_m),
        ):
            points.append(shapely.Point(trigger[f"{vessel}_east_m"], trigger[f"{vessel}_north_m"]))
            point_rows.append({**rows.iloc[index].to_dict(), "vessel": vessel})
            line = track.dropna()
            if len(line) >= 2:
                tracks.append(shapely.LineString(line[["east_m", "north_m"]].to_numpy()))
                track_rows.append(
                    {
                        "encounter_id": outcome.summary.encounter_id,
                        "vessel": vessel,
                        "mmsi": getattr(outcome.summary, f"{vessel}_mmsi"),
                    }
                )
            cpa.append(shapely.Point(at_tcpa[1], at_tcpa[0]))
            cpa_rows.append(
                {
                    "encounter_id": outcome.summary.encounter_id,
                    "vessel": vessel,
                    "mmsi": getattr(outcome.summary, f"{vessel}_mmsi"),
                    "tcpa_s": outcome.summary.tcpa_s,
                }
            )
    layers["encounters"] = (_to_wgs84(frame, points), pd.DataFrame(point_rows))
    layers["tracks"] = (_to_wgs84(frame, tracks), pd.DataFrame(track_rows))
    layers["cpa"] = (_to_wgs84(frame, cpa), pd.DataFrame(cpa_rows))
    domains: list[Any] = []
    domain_rows: list[pd.DataFrame] = []
    for outcome in outcomes:
        assessment = outcome.assessment
        domains.extend(assessment.ellipses)
        domain_rows.append(
            pd.DataFrame(
                {
                    "encounter_id": outcome.summary.encounter_id,
                    "target_mmsi": outcome.summary.target_mmsi,
                    "arc": assessment.arc.astype(object),
                    "step": assessment.step,
                    "restricted": assessment.restricted & assessment.covered,
                    "covered": assessment.covered,
                    "state": np.where(
                        ~assessment.covered,
                        "unknown",
                        np.where(assessment.restricted, "restricted", "clear"),
                    ).astype(object),
                    "verdict": assessment.restriction.value,
                }
            )
        )
    layers["domains"] = (_to_wgs84(frame, domains), pd.concat(domain_rows, ignore_index=True))
    if chart is not None:
        draughts = sorted({o.summary.target_draught_m for o in outcomes})
        ukc_m = result.params.manoeuvrability.ukc_m
        water = [chart.navigable_water(d, ukc_m) for d in draughts]
        layers["navigable_water"] = (
            _to_wgs84(frame, water),
            pd.DataFrame({"draught_m": draughts, "ukc_m": ukc_m}),
        )
    with atomic_path(path, suffix=".gpkg") as tmp:
        tmp.unlink()  # GDAL creates the GeoPackage itself
        written = 0
        for layer, (wkb, table) in layers.items():
            if len(wkb) == 0:
                continue
            values, names = _fields(table)
            pyogrio.raw.write(
                tmp,
                wkb,
                values,
                names,
                layer=layer,
                driver="GPKG",
                geometry_type=_geometry_type(layer),
                crs="EPSG:4326",
                promote_to_multi=layer in ("domains", "navigable_water"),
                append=written > 0,
            )
            written += 1
        add_layer_styles(tmp, [name for name, (wkb, _) in layers.items() if len(wkb)])
    return path


def _geometry_type(layer: str) -> str:
    return {
        "encounters": "Point",
        "cpa": "Point",
        "tracks": "LineString",
        "domains": "MultiPolygon",
        "navigable_water": "MultiPolygon",
    }[layer]
