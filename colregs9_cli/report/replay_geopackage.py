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
  ``covered`` (booleans), ``state`` (restricted, clear or unknown), ``arc`` and ``step``:
  all of them, only the restricted ones (the default: those an auditor checks against the
  chart; 3,907 of the San Diego fixture's 13,680) or none (``Domains``);
- ``vessel_tracks``: every vessel's track over the run (``ReplayResult.vessel_tracks``), a
  line per piece (a vessel's track is split where her reports stop for longer than
  ``max_gap_s`` or jump), with time as the M value of each vertex (seconds since the Unix
  epoch, UTC) and ``start_utc``/``end_utc``, so that QGIS's Temporal Controller can play
  them; a piece of one report is no line: it is in ``lone_reports``. Cut at the
  antimeridian;
- ``lone_reports``: the pieces too short for a line (one report, or reports within the same
  10 s of thinning: a vessel heard once, or at rest reporting further apart than
  ``max_gap_s``) as points, with the same fields (``start_utc`` = ``end_utc``), so that
  every vessel of the run is in the file;
- ``navigable_water``: the water deep enough for each target draught used, where a chart was
  given;
- ``channels`` and ``channel_axes``: the charted channel areas a vessel of a triggered pair
  was in (at the trigger or the least separation), with their names and measures, and their
  axes (``charts.channels``).

The file is GeoPackage 1.3, which GDAL reads without a warning from 3.3 on (the 1.4 that
GDAL 3.12 writes by default makes GDAL 3.6, Debian 12's, warn that it "may only be partially
supported"); M coordinates are GDAL's since 2.1.

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
from collections.abc import Iterator, Sequence
from enum import Enum, StrEnum
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyogrio
import shapely

from ..charts.channels import Channels, load_channels
from ..charts.water import Chart
from ..core.replay_results import EncounterOutcome, EncounterSummary, ReplayResult
from ..geo import LocalFrame
from ..outputs import atomic_path
from .qgis_styles import add_layer_styles

GEOPACKAGE_NAME = "report.gpkg"


class Domains(StrEnum):
    """Which ship-domain ellipses go into the ``domains`` layer."""

    ALL = "all"
    RESTRICTED = "restricted"  # those not inside navigable water, where the chart covers them
    NONE = "none"


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
    table = table.astype({name: _dtype(hint) for name, hint in hints.items()})
    # A text column's missing values as None whatever the rows (pandas makes them NaN
    # beside text, and keeps None in a column of none), so that parts join as the whole.
    text = [name for name in table.columns if table[name].dtype == object]
    table[text] = table[text].astype(object).where(table[text].notna(), None)
    return table


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


def encounter_layers(
    outcomes: Sequence[EncounterOutcome], frame: LocalFrame, domains: Domains = Domains.RESTRICTED
) -> dict[str, Layer]:
    """The layers drawn from the encounters themselves (``encounters``, ``tracks``, ``cpa``
    and, unless ``domains`` is none, ``domains``), for ``outcomes`` (at least one) in their
    order; ``frame``: the run's. Layers of consecutive parts of the encounters, joined in
    order (``join_layers``), are the layers of the whole: every column's type is fixed,
    whatever values a part holds."""
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
    layers = {
        "encounters": (np.asarray(points, dtype=object), point_rows),
        "tracks": (
            np.asarray(tracks, dtype=object),
            pd.DataFrame(track_rows, columns=["encounter_id", "vessel", "mmsi"]),
        ),
        "cpa": (np.asarray(cpa, dtype=object), pd.DataFrame(cpa_rows).astype({"tcpa_s": float})),
    }
    if domains is not Domains.NONE:
        layers["domains"] = _domain_layer(outcomes, frame, domains)
    return layers


def _domain_layer(
    outcomes: Sequence[EncounterOutcome], frame: LocalFrame, domains: Domains
) -> Layer:
    """The ellipses of each outcome's assessment (only the restricted ones for
    ``Domains.RESTRICTED``)."""
    ellipses: list[Any] = []
    domain_rows: list[pd.DataFrame] = []
    for outcome in outcomes:
        assessment = outcome.assessment
        restricted = assessment.restricted & assessment.covered
        kept = restricted if domains is Domains.RESTRICTED else np.ones(len(restricted), bool)
        ellipses.extend(assessment.ellipses[kept])
        domain_rows.append(
            pd.DataFrame(
                {
                    "encounter_id": outcome.summary.encounter_id,
                    "target_mmsi": outcome.summary.target_mmsi,
                    "arc": assessment.arc.astype(object),
                    "step": assessment.step,
                    "restricted": restricted,
                    "covered": assessment.covered,
                    "state": np.where(
                        ~assessment.covered,
                        "unknown",
                        np.where(assessment.restricted, "restricted", "clear"),
                    ).astype(object),
                    "verdict": assessment.restriction.value,
                }
            )[kept]
        )
    table = pd.concat(domain_rows, ignore_index=True).astype(
        {"target_mmsi": np.int64, "step": np.int64, "restricted": bool, "covered": bool}
    )
    return _to_wgs84(frame, ellipses), table


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
    domains: Domains = Domains.RESTRICTED,
) -> None:
    """Write ``report.gpkg`` (see the module docstring) of a result with at least one
    encounter (without, the report has no GeoPackage). ``parts``: ``encounter_layers`` of
    consecutive parts of ``result.encounters``, made where those are with the same
    ``domains`` (default: made here)."""
    outcomes = result.encounters
    frame = result.frame
    layers = join_layers(parts) if parts else encounter_layers(outcomes, frame, domains)
    layers["vessel_tracks"] = vessel_track_layer(result.vessel_tracks)
    layers["lone_reports"] = lone_report_layer(result.vessel_tracks)
    if chart is not None:
        draughts = sorted({o.summary.target_draught_m for o in outcomes})
        ukc_m = result.params.manoeuvrability.ukc_m
        water = [chart.navigable_water(d, ukc_m) for d in draughts]
        layers["navigable_water"] = (
            _to_wgs84(frame, water),
            pd.DataFrame({"draught_m": draughts, "ukc_m": ukc_m}),
        )
        layers.update(channel_layers(load_channels(chart), _channels_used(result), frame))
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
                geometry_type=GEOMETRY_TYPES[layer],
                crs="EPSG:4326",
                # Tracks and domains cut at the antimeridian are multi-part.
                promote_to_multi=layer
                in ("tracks", "domains", "navigable_water", "channels", "channel_axes"),
                append=written > 0,
                **({} if written else {"dataset_options": {"VERSION": "1.3"}}),
            )
            written += 1
        add_layer_styles(tmp, [name for name, (wkb, _) in layers.items() if len(wkb)])


GEOMETRY_TYPES = {
    "encounters": "Point",
    "cpa": "Point",
    "tracks": "MultiLineString",
    "domains": "MultiPolygon",
    "vessel_tracks": "Measured MultiLineString",
    "lone_reports": "Point",
    "navigable_water": "MultiPolygon",
    "channels": "MultiPolygon",
    "channel_axes": "MultiLineString",
}


def _channels_used(result: ReplayResult) -> set[str]:
    """The charted channels a vessel of a triggered pair was in, at the trigger or at the
    least separation."""
    return {
        name
        for pair in result.pairs
        for field in ("channel", "channel_at_min_separation")
        for vessel in ("a", "b")
        if (name := getattr(pair.summary, f"{field}_{vessel}"))
    }


def channel_layers(channels: Channels, used: set[str], frame: LocalFrame) -> dict[str, Layer]:
    """The channel areas in ``used`` (by label), with what names and measures them, and
    their axes."""
    items = [c for c in channels if c.is_area and c.label in used]
    table = pd.DataFrame(
        {
            "label": [c.label for c in items],
            "kind": [c.kind.value for c in items],
            "record_id": [c.record_id for c in items],
            "name": [c.name for c in items],
            "orient_deg": [c.orient_deg for c in items],
            "axis_source": [c.axis_source.value for c in items],
            "axis_deg": [c.axis_deg for c in items],
            "depth_m": [c.depth_m for c in items],
            "width_m": [c.width_m for c in items],
            "length_m": [c.length_m for c in items],
        }
    ).astype({"orient_deg": float, "axis_deg": float, "depth_m": float, "width_m": float})
    return {
        "channels": (_to_wgs84(frame, [c.geometry for c in items]), table),
        "channel_axes": (_to_wgs84(frame, [c.axis for c in items]), table[["label", "kind"]]),
    }


# Pieces turned into geometries at a time: the text of this many vertices is held at once.
_CHUNK_VERTICES = 200_000


def _pieces(vertices: pd.DataFrame, lines: bool) -> tuple[np.ndarray, np.ndarray, pd.DataFrame]:
    """The pieces of ``ReplayResult.vessel_tracks`` of two vertices or more (``lines``) or
    of one: where each starts and ends in the vertices, and a row of fields per piece."""
    mmsi = vertices["mmsi"].to_numpy(dtype=np.int64)
    piece = vertices["piece"].to_numpy(dtype=np.int64)
    starts = np.flatnonzero(np.r_[True, (mmsi[1:] != mmsi[:-1]) | (piece[1:] != piece[:-1])])
    ends = np.r_[starts[1:], len(mmsi)].astype(np.int64)
    wanted = ((ends - starts >= 2) == lines) & (ends > starts)
    starts, ends = starts[wanted], ends[wanted]
    t_s = vertices["t_s"].to_numpy(dtype=float)
    first = vertices.iloc[starts]
    reports = vertices["reports"].to_numpy(dtype=np.int64).cumsum()
    table = pd.DataFrame(
        {
            "mmsi": mmsi[starts],
            "piece": piece[starts],
            "name": first["name"].astype(object).to_numpy(),
            "ship_type": first["ship_type"].astype(object).to_numpy(),
            "length_m": pd.to_numeric(first["length_m"].astype(object)).to_numpy(dtype=float),
            "start_utc": _utc(t_s[starts]),
            "end_utc": _utc(t_s[ends - 1]),
            "reports": reports[ends - 1] - np.r_[0, reports][starts],
        }
    )
    return starts, ends, table


def lone_report_layer(vertices: pd.DataFrame) -> Layer:
    """``lone_reports`` (module docstring): a point per piece of one vertex, so that every
    vessel of the run is in the GeoPackage."""
    starts, _, table = _pieces(vertices, lines=False)
    points = shapely.points(
        vertices["lon_deg"].to_numpy(dtype=float)[starts],
        vertices["lat_deg"].to_numpy(dtype=float)[starts],
    )
    return np.asarray(shapely.to_wkb(points, flavor="iso"), dtype=object), table


def vessel_track_layer(vertices: pd.DataFrame) -> Layer:
    """``vessel_tracks`` (module docstring) from ``ReplayResult.vessel_tracks``: a feature
    per piece of two vertices or more, in the order of the vertices (by MMSI and time)."""
    starts, ends, table = _pieces(vertices, lines=True)
    t_s = vertices["t_s"].to_numpy(dtype=float)
    lon = vertices["lon_deg"].to_numpy(dtype=float)
    lat = vertices["lat_deg"].to_numpy(dtype=float)
    wkb = [np.zeros(0, dtype=object)]
    for some_starts, some_ends in _chunks(starts, ends):
        wkt = [
            _wkt(lon[a:b], lat[a:b], t_s[a:b]) for a, b in zip(some_starts, some_ends, strict=True)
        ]
        wkb.append(np.asarray(shapely.to_wkb(shapely.from_wkt(wkt), flavor="iso"), dtype=object))
    return np.concatenate(wkb), table


def _utc(t_s: np.ndarray) -> pd.Series:
    """Epoch seconds as UTC times, to the millisecond (the reports' resolution)."""
    milliseconds = np.round(t_s * 1000.0).astype(np.int64)
    return pd.Series(pd.to_datetime(milliseconds, unit="ms", utc=True))


def _chunks(starts: np.ndarray, ends: np.ndarray) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The pieces ``starts[i]:ends[i]`` in runs of about ``_CHUNK_VERTICES`` vertices."""
    i = 0
    while i < len(starts):
        j = max(i + 1, int(np.searchsorted(ends, starts[i] + _CHUNK_VERTICES, side="right")))
        yield starts[i:j], ends[i:j]
        i = j


def _wkt(lon: np.ndarray, lat: np.ndarray, t_s: np.ndarray) -> str:
    """A piece as WKT ``MULTILINESTRING M`` with time as M, in one part, or cut where it
    crosses the antimeridian (as RFC 7946 asks): the crossing, interpolated, ends one part
    at ±180° and starts the next at ∓180°. Python's shortest repr of each coordinate reads
    back as the same float."""
    coordinates = list(zip(lon.tolist(), lat.tolist(), t_s.tolist(), strict=True))
    parts = []
    start = 0
    for i in np.flatnonzero(np.abs(np.diff(lon)) > 180.0).tolist():
        (lon_a, lat_a, t_a), (lon_b, lat_b, t_b) = coordinates[i], coordinates[i + 1]
        edge = 180.0 if lon_a > 0.0 else -180.0
        fraction = (edge - lon_a) / (lon_b + 2.0 * edge - lon_a)  # lon_b unwrapped
        lat_c, t_c = lat_a + fraction * (lat_b - lat_a), t_a + fraction * (t_b - t_a)
        parts.append([*coordinates[start : i + 1], (edge, lat_c, t_c)])
        coordinates[i] = (-edge, lat_c, t_c)  # the next part's first vertex
        start = i
    parts.append(coordinates[start:])
    lines = ", ".join(
        "(" + ", ".join(f"{x!r} {y!r} {m!r}" for x, y, m in part) + ")" for part in parts
    )
    return f"MULTILINESTRING M ({lines})"
