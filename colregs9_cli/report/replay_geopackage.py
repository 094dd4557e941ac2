"""``report.gpkg``: the replay's encounters for QGIS, in WGS84, written with GDAL (pyogrio).

Layers (each only when it has features):

- ``encounters``: a point at each vessel's position at the trigger, one per vessel and
  encounter row, with every ``encounters.csv`` column and ``vessel`` (own or target).
  ``action_before_cpa_s`` is the point's vessel's: how long before CPA she acted, empty when
  she is not a give-way vessel or did not act (encounters.csv lists the give-way vessels'
  values, ``;``-separated);
- ``tracks``: each vessel's track over the encounter, a line per vessel and encounter;
- ``cpa``: each vessel's position predicted at TCPA from the trigger;
- ``domains``: the target's ship-domain ellipses at the trigger, with ``restricted`` and
  ``covered`` (booleans), ``state`` (restricted, clear or unknown), ``arc`` and ``step``;
- ``navigable_water``: the water deep enough for each target draught used, where a chart was
  given.

Fields are typed as their values: MMSIs, steps and navigational statuses as integers (empty
when none), two-valued flags as booleans, measurements as reals, times as UTC date-times;
three-valued facts (``true``, ``false``, ``insufficient-data`` or ``unknown``) and the other
codes stay text. Each layer carries a default QGIS style in the ``layer_styles`` table
(``qgis_styles.py``).
"""

from __future__ import annotations

import dataclasses
import types
import typing
from collections.abc import Sequence
from enum import Enum
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyogrio
import shapely

from ..charts.water import Chart
from ..core.replay_results import EncounterOutcome, EncounterSummary, ReplayResult
from ..geo import LocalFrame
from ..outputs import atomic_path
from .qgis_styles import add_layer_styles

GEOPACKAGE_NAME = "report.gpkg"


def _to_wgs84(frame: LocalFrame, geometries: Any) -> np.ndarray:
    return np.asarray(shapely.to_wkb(frame.shapes_to_wgs84(geometries)), dtype=object)


# GDAL's time-zone flag for UTC (1 is local time, 100 + n is n quarter-hours east of UTC).
GDAL_UTC = 100


@dataclasses.dataclass
class _Fields:
    """A layer's attribute columns as ``pyogrio.raw.write`` takes them."""

    values: list[np.ndarray]
    names: list[str]
    masks: list[np.ndarray | None]
    tz_offsets: dict[str, np.ndarray]


def _fields(table: pd.DataFrame) -> _Fields:
    """Columns as GDAL fields by their dtype: integers (nullable) as integers, booleans as
    booleans, floats as reals, UTC times as date-times, everything else as text."""
    fields = _Fields([], [], [], {})
    for name in table.columns:
        column = table[name]
        missing = column.isna().to_numpy()
        mask = missing if missing.any() else None
        if pd.api.types.is_bool_dtype(column):
            values = column.to_numpy(dtype=bool, na_value=False)
        elif pd.api.types.is_integer_dtype(column):
            values = column.to_numpy(dtype=np.int64, na_value=0)
        elif pd.api.types.is_float_dtype(column):
            values, mask = column.to_numpy(dtype=float, na_value=np.nan), None
        elif isinstance(column.dtype, pd.DatetimeTZDtype):
            values = column.dt.tz_convert("UTC").dt.tz_localize(None).to_numpy("datetime64[ms]")
            fields.tz_offsets[str(name)] = np.full(len(column), GDAL_UTC)
            mask = None  # NaT is written as null
        else:
            values = column.astype(str).to_numpy(dtype=object)
            values[missing] = None
            mask = None
        fields.values.append(values)
        fields.names.append(str(name))
        fields.masks.append(mask)
    return fields


def _dtype(annotation: Any) -> str:
    """The pandas dtype of an ``EncounterSummary`` field (``X | None`` as X, nullable)."""
    optional = isinstance(annotation, types.UnionType)
    if optional:
        annotation = next(a for a in typing.get_args(annotation) if a is not type(None))
    if annotation is bool:
        return "boolean" if optional else "bool"  # empty stays empty, never false
    if annotation is int:
        return "Int64"
    if annotation is float:
        return "float64"
    if annotation is pd.Timestamp:
        return "datetime64[ns, UTC]"
    return "object"


def _encounter_table(outcomes: Sequence[EncounterOutcome]) -> pd.DataFrame:
    """encounters.csv's rows with their values' types (enums as their text)."""
    records = [
        {
            name: value.value if isinstance(value, Enum) else value
            for name, value in dataclasses.asdict(outcome.summary).items()
        }
        for outcome in outcomes
    ]
    hints = typing.get_type_hints(EncounterSummary)
    table = pd.DataFrame.from_records(records, columns=list(hints))
    return table.astype({name: _dtype(hint) for name, hint in hints.items()})


def _action_before_cpa_s(summary: EncounterSummary, mmsi: int) -> float:
    """How long before CPA the vessel ``mmsi`` acted, NaN when she is not a give-way vessel
    or did not act (``give_way_vessels`` and ``action_before_cpa_s`` list the give-way
    vessels in the same order)."""
    give_way = (summary.give_way_vessels or "").split(";")
    seconds = (summary.action_before_cpa_s or "").split(";")
    if str(mmsi) not in give_way:
        return float("nan")
    value = seconds[give_way.index(str(mmsi))]
    return float(value) if value else float("nan")


# A layer's geometries (WKB in WGS84) and its attribute rows, one per geometry.
Layer = tuple[np.ndarray, pd.DataFrame]


def encounter_layers(outcomes: Sequence[EncounterOutcome], frame: LocalFrame) -> dict[str, Layer]:
    """The layers drawn from the encounters themselves (all but ``navigable_water``), for
    ``outcomes`` (at least one) in their order; ``frame``: the run's. Layers of consecutive
    parts of the encounters, joined in order (``join_layers``), are the layers of the whole:
    every column's type is fixed, whatever values a part holds."""
    points: list[Any] = []
    tracks: list[Any] = []
    cpa: list[Any] = []
    actions: list[float] = []
    track_rows: list[dict[str, Any]] = []
    cpa_rows: list[dict[str, Any]] = []
    for outcome in outcomes:
        # Each outcome's metres are in its own frame (the run's, or the pair's beyond its
        # reach): its geometries go to WGS84 through that frame.
        its_points: list[Any] = []
        its_tracks: list[Any] = []
        its_cpa: list[Any] = []
        for vessel, track, at_trigger, at_tcpa in (
            ("own", outcome.own_track, outcome.own_at_trigger_m, outcome.own_at_tcpa_m),
            ("target", outcome.target_track, outcome.target_at_trigger_m, outcome.target_at_tcpa_m),
        ):
            mmsi = getattr(outcome.summary, f"{vessel}_mmsi")
            its_points.append(shapely.Point(at_trigger[1], at_trigger[0]))
            actions.append(_action_before_cpa_s(outcome.summary, mmsi))
            line = track.dropna()
            if len(line) >= 2:
                its_tracks.append(shapely.LineString(line[["east_m", "north_m"]].to_numpy()))
                track_rows.append(
                    {
                        "encounter_id": outcome.summary.encounter_id,
                        "vessel": vessel,
                        "mmsi": mmsi,
                    }
                )
            its_cpa.append(shapely.Point(at_tcpa[1], at_tcpa[0]))
            cpa_rows.append(
                {
                    "encounter_id": outcome.summary.encounter_id,
                    "vessel": vessel,
                    "mmsi": mmsi,
                    "tcpa_s": outcome.summary.tcpa_s,
                }
            )
        points.extend(_to_wgs84(outcome.frame, its_points))
        tracks.extend(_to_wgs84(outcome.frame, its_tracks))
        cpa.extend(_to_wgs84(outcome.frame, its_cpa))
    # Each encounter row twice, own ship's point then the target's.
    table = _encounter_table(outcomes)
    point_rows = table.loc[table.index.repeat(2)].reset_index(drop=True)
    point_rows = point_rows.assign(
        action_before_cpa_s=actions, vessel=["own", "target"] * len(outcomes)
    )
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
    return {
        "encounters": (np.asarray(points, dtype=object), point_rows),
        "tracks": (
            np.asarray(tracks, dtype=object),
            pd.DataFrame(track_rows, columns=["encounter_id", "vessel", "mmsi"]),
        ),
        "cpa": (np.asarray(cpa, dtype=object), pd.DataFrame(cpa_rows).astype({"tcpa_s": float})),
        "domains": (_to_wgs84(frame, domains), pd.concat(domain_rows, ignore_index=True)),
    }


def join_layers(parts: Sequence[dict[str, Layer]]) -> dict[str, Layer]:
    """The layers of consecutive parts of the encounters, in order."""
    joined: dict[str, Layer] = {}
    for name in parts[0]:
        filled = [part[name] for part in parts if len(part[name][0])] or [parts[0][name]]
        joined[name] = (
            np.concatenate([wkb for wkb, _ in filled]),
            pd.concat([table for _, table in filled], ignore_index=True),
        )
    return joined


def write_replay_geopackage(
    path: Path,
    result: ReplayResult,
    chart: Chart | None,
    parts: Sequence[dict[str, Layer]] | None = None,
) -> None:
    """Write ``report.gpkg`` (see the module docstring) of a result with at least one
    encounter (without, the report has no GeoPackage). ``parts``: ``encounter_layers`` of
    consecutive parts of ``result.encounters``, made where those are (default: made here)."""
    outcomes = result.encounters
    frame = result.frame
    layers = join_layers(parts) if parts else encounter_layers(outcomes, frame)
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
            fields = _fields(table)
            pyogrio.raw.write(
                tmp,
                wkb,
                fields.values,
                fields.names,
                field_mask=fields.masks,
                gdal_tz_offsets=fields.tz_offsets,
                layer=layer,
                driver="GPKG",
                geometry_type=_geometry_type(layer),
                crs="EPSG:4326",
                # Tracks and domains cut at the antimeridian are multi-part.
                promote_to_multi=layer in ("tracks", "domains", "navigable_water"),
                append=written > 0,
            )
            written += 1
        add_layer_styles(tmp, [name for name, (wkb, _) in layers.items() if len(wkb)])


def _geometry_type(layer: str) -> str:
    return {
        "encounters": "Point",
        "cpa": "Point",
        "tracks": "MultiLineString",
        "domains": "MultiPolygon",
        "navigable_water": "MultiPolygon",
    }[layer]
