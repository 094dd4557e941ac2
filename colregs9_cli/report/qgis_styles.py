"""Default QGIS styles for ``report.gpkg``, stored in the GeoPackage's ``layer_styles`` table.

QGIS reads that table (its own extension to GeoPackage) when it opens a layer and applies the
style marked ``useAsDefault``, so the layers open drawn as in the report's figures: own ship
dark orange and the target black, restricted ellipses red and clear ones blue (outlines
only), the navigable water outlined green. Each style is a QML document with one renderer
(``renderer-v2``), single-symbol or categorized on a field of the layer; GDAL does not know
the table, so it is added with SQLite after GDAL has written the layers.

``vessel_tracks`` comes with its Temporal Controller settings (each piece shown from its
``start_utc`` to its ``end_utc``) and two geometry-generator layers over its grey line, made
from the M values (epoch seconds) of its vertices at the animation frame's end: the track
sailed so far, and a marker at the vessel's position, interpolated between the two vertices
around that time. The expressions use only functions QGIS has had since 3.16 (checked with
QGIS 3.22, Debian 12's).
"""

from __future__ import annotations

import sqlite3
from collections.abc import Sequence
from contextlib import closing
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from xml.sax.saxutils import quoteattr

OWN_RGBA = "255,140,0,255"
TARGET_RGBA = "0,0,0,255"
RESTRICTED_RGBA = "214,39,40,255"
CLEAR_RGBA = "31,119,180,255"
UNKNOWN_RGBA = "127,127,127,255"
WATER_RGBA = "0,200,83,255"
VESSEL_RGBA = "0,110,120,255"
PAST_RGBA = "160,160,160,255"
CHANNEL_RGBA = "148,103,189,255"  # matplotlib's tab:purple, as in the figures
TRANSPARENT = "0,0,0,0"

# The vertices of a vessel_tracks piece, and the time at the end of the animation frame in
# epoch seconds (NULL when the Temporal Controller is off: nothing is generated).
_VERTICES = "array_foreach(generate_series(1, num_points($geometry)), point_n($geometry, @element))"
_FRAME_END_S = "epoch(@map_end_time) / 1000"
SAILED_SO_FAR = f"make_line(array_filter({_VERTICES}, m(@element) <= {_FRAME_END_S}))"
# With k vertices at or before the frame's end: between the k-th and the next, in
# proportion to the time, or the last vertex once the piece has ended.
POSITION_AT_FRAME = (
    f"with_variable('t', {_FRAME_END_S}, with_variable('v', {_VERTICES}, "
    "with_variable('k', array_length(array_filter(@v, m(@element) <= @t)), "
    "if(@k < 1, NULL, if(@k >= array_length(@v), @v[-1], "
    "line_interpolate_point(make_line(@v[@k - 1], @v[@k]), "
    "length(make_line(@v[@k - 1], @v[@k])) * (@t - m(@v[@k - 1])) "
    "/ (m(@v[@k]) - m(@v[@k - 1]))))))))"
)


@dataclass(frozen=True)
class Symbol:
    """One QGIS symbol layer: ``kind`` is marker, line or fill."""

    kind: str
    colour: str
    dashed: bool = False
    marker: str = "circle"
    width: str = "0.5"
    # Geometry-generator layers drawn over this one: (expression, symbol of its geometry).
    generated: Sequence[tuple[str, Symbol]] = ()

    def qml(self, name: str) -> str:
        if self.kind == "marker":
            layer_class, options = (
                "SimpleMarker",
                {
                    "name": self.marker,
                    "color": self.colour,
                    "outline_color": "255,255,255,255",
                    "size": "2.6",
                },
            )
        elif self.kind == "line":
            layer_class, options = (
                "SimpleLine",
                {
                    "line_color": self.colour,
                    "line_width": self.width,
                    "line_style": "dash" if self.dashed else "solid",
                },
            )
        else:
            layer_class, options = (
                "SimpleFill",
                {
                    "color": TRANSPARENT,
                    "style": "no",
                    "outline_color": self.colour,
                    "outline_width": "0.4",
                    "outline_style": "solid",
                },
            )
        option_lines = "".join(
            f'<Option type="QString" name={quoteattr(k)} value={quoteattr(v)}/>'
            for k, v in options.items()
        )
        generators = "".join(
            '<layer class="GeometryGenerator" enabled="1" locked="0" pass="0">'
            '<Option type="Map">'
            f'<Option type="QString" name="SymbolType" value="{symbol.kind.title()}"/>'
            f'<Option type="QString" name="geometryModifier" value={quoteattr(expression)}/>'
            '<Option type="QString" name="units" value="MapUnit"/></Option>'
            f"{symbol.qml(f'@{name}@{i}')}</layer>"
            for i, (expression, symbol) in enumerate(self.generated, start=1)
        )
        return (
            f'<symbol type="{self.kind}" name={quoteattr(name)} alpha="1" clip_to_extent="1" '
            'force_rhr="0">'
            f'<layer class="{layer_class}" enabled="1" locked="0" pass="0">'
            f'<Option type="Map">{option_lines}</Option></layer>{generators}</symbol>'
        )


@dataclass(frozen=True)
class Style:
    """A layer's renderer: one symbol, or one per value of ``field``."""

    layer: str
    description: str
    symbol: Symbol | None = None
    field: str | None = None
    categories: Sequence[tuple[str, str, Symbol]] = ()
    # The Temporal Controller's "separate fields for start and end date/time" (QGIS's mode 2).
    start_end_fields: tuple[str, str] | None = None
    # Whether a frame that begins at a feature's end still shows it (QGIS's limit mode 1):
    # a feature whose start is its end shows in no frame otherwise.
    include_end: bool = False

    def qml(self) -> str:
        if self.field is None:
            assert self.symbol is not None
            renderer = (
                '<renderer-v2 type="singleSymbol" forceraster="0" symbollevels="0" '
                f'enableorderby="0"><symbols>{self.symbol.qml("0")}</symbols></renderer-v2>'
            )
        else:
            categories = "".join(
                f'<category render="true" value={quoteattr(value)} label={quoteattr(label)} '
                f'symbol="{i}"/>'
                for i, (value, label, _) in enumerate(self.categories)
            )
            symbols = "".join(s.qml(str(i)) for i, (_, _, s) in enumerate(self.categories))
            renderer = (
                f'<renderer-v2 type="categorizedSymbol" attr={quoteattr(self.field)} '
                'forceraster="0" symbollevels="0" enableorderby="0">'
                f"<categories>{categories}</categories><symbols>{symbols}</symbols>"
                "</renderer-v2>"
            )
        temporal = ""
        if self.start_end_fields is not None:
            start, end = self.start_end_fields
            temporal = (
                f'<temporal enabled="1" mode="2" startField={quoteattr(start)} '
                f'endField={quoteattr(end)} accumulate="0" limitMode="{int(self.include_end)}">'
                "<fixedRange><start></start><end></end></fixedRange></temporal>"
            )
        categories = "Symbology|Temporal" if temporal else "Symbology"
        return (
            "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>"
            f'<qgis version="3.28.0" styleCategories="{categories}">{temporal}{renderer}</qgis>'
        )


STYLES: tuple[Style, ...] = (
    Style(
        "encounters",
        "each vessel at the trigger: own ship orange, target black",
        field="vessel",
        categories=(
            ("own", "own ship", Symbol("marker", OWN_RGBA, marker="square")),
            ("target", "target", Symbol("marker", TARGET_RGBA, marker="square")),
        ),
    ),
    Style(
        "tracks",
        "tracks: own ship orange, target black dashed",
        field="vessel",
        categories=(
            ("own", "own ship", Symbol("line", OWN_RGBA)),
            ("target", "target", Symbol("line", TARGET_RGBA, dashed=True)),
        ),
    ),
    Style(
        "cpa",
        "positions predicted at TCPA: own ship red, target black",
        field="vessel",
        categories=(
            ("own", "own ship at TCPA", Symbol("marker", RESTRICTED_RGBA)),
            ("target", "target at TCPA", Symbol("marker", TARGET_RGBA)),
        ),
    ),
    Style(
        "domains",
        "ship domains: restricted red, clear blue, off the chart grey (outlines)",
        field="state",
        categories=(
            ("restricted", "restricted", Symbol("fill", RESTRICTED_RGBA)),
            ("clear", "clear", Symbol("fill", CLEAR_RGBA)),
            ("unknown", "off the chart (unknown)", Symbol("fill", UNKNOWN_RGBA)),
        ),
    ),
    Style(
        "vessel_tracks",
        "every vessel's track, grey; animated by the Temporal Controller: the track sailed "
        "so far and the vessel's position",
        symbol=Symbol(
            "line",
            PAST_RGBA,
            width="0.3",
            generated=(
                (SAILED_SO_FAR, Symbol("line", VESSEL_RGBA)),
                (POSITION_AT_FRAME, Symbol("marker", VESSEL_RGBA)),
            ),
        ),
        start_end_fields=("start_utc", "end_utc"),
    ),
    Style(
        "lone_reports",
        "the vessels heard too briefly for a track (one report, or at rest reporting "
        "further apart than max_gap_s), shown at the time of each report",
        symbol=Symbol("marker", VESSEL_RGBA),
        start_end_fields=("start_utc", "end_utc"),
        include_end=True,
    ),
    Style(
        "navigable_water",
        "navigable water for the draught, outlined green",
        symbol=Symbol("fill", WATER_RGBA),
    ),
    Style(
        "channels",
        "charted channels a vessel was in, outlined purple",
        symbol=Symbol("fill", CHANNEL_RGBA),
    ),
    Style(
        "channel_axes",
        "their axes, purple dashed",
        symbol=Symbol("line", CHANNEL_RGBA, dashed=True),
    ),
)


def add_layer_styles(path: Path, layers: Sequence[str]) -> None:
    """Store the default style of each of ``layers`` in the GeoPackage at ``path``."""
    # GeoPackage DATETIME: with milliseconds, else GDAL warns "Non-conformant content".
    now = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%S.000Z")
    with closing(sqlite3.connect(path)) as db, db:
        db.execute(
            "CREATE TABLE IF NOT EXISTS layer_styles ("
            "id INTEGER PRIMARY KEY AUTOINCREMENT, f_table_catalog TEXT(256), "
            "f_table_schema TEXT(256), f_table_name TEXT(256), f_geometry_column TEXT(256), "
            "styleName TEXT(30), styleQML TEXT, styleSLD TEXT, useAsDefault BOOLEAN, "
            "description TEXT, owner TEXT(30), ui TEXT(30), update_time DATETIME)"
        )
        # Registered as an attribute table, as QGIS registers it itself.
        db.execute(
            "INSERT OR IGNORE INTO gpkg_contents (table_name, data_type, identifier) "
            "VALUES ('layer_styles', 'attributes', 'layer_styles')"
        )
        for style in STYLES:
            if style.layer not in layers:
                continue
            (geometry_column,) = db.execute(
                "SELECT column_name FROM gpkg_geometry_columns WHERE table_name = ?",
                (style.layer,),
            ).fetchone()
            db.execute(
                "INSERT INTO layer_styles (f_table_catalog, f_table_schema, f_table_name, "
                "f_geometry_column, styleName, styleQML, styleSLD, useAsDefault, description, "
                "owner, ui, update_time) VALUES ('', '', ?, ?, ?, ?, '', 1, ?, 'colregs9', "
                "'', ?)",
                (
                    style.layer,
                    geometry_column,
                    f"colregs9 {style.layer}",
                    style.qml(),
                    style.description,
                    now,
                ),
            )
