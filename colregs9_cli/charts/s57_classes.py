"""The S-57 object classes a chart is read for, and the role each plays in it.

Object classes used: DEPARE and DRGARE (dredged areas count as depth areas), LNDARE (land),
PONTON, HULKES, FLODOC and DRYDOC areas (structures that cut holes in the depth areas; they
are treated like land), and OBSTRN, WRECKS and UWTROC as point hazards.

One table (``OBJECT_CLASSES``) serves the reader (``read``), which keeps the features of
these classes only, and the chart (``sources``, ``water``), which sorts them by role into
depth areas, land and hazards: a class is added in one place.

A second table (``CHANNEL_CLASSES``) holds the routeing objects that rules 9 and 10 speak of,
each with its ``ChannelKind``: the areas FAIRWY (fairway), DRGARE (dredged area, which is
also a depth area above), DWRTPT (deep-water route part), TSSLPT (traffic separation scheme
lane part) and TSEZNE (separation zone), and the lines RECTRC (recommended track), NAVLNE
(navigation line), TSELNE (separation line) and TSSBND (scheme boundary). ``channels`` reads
them, with their names and attributes; the navigable water does not.
"""

from __future__ import annotations

from enum import StrEnum

import shapely


class ChartLayer(StrEnum):
    """The role a chart feature plays."""

    DEPARE = "DEPARE"
    DRGARE = "DRGARE"
    LNDARE = "LNDARE"
    HAZARD = "HAZARD"


# S-57 object class acronym → (numeric code, role).
OBJECT_CLASSES: dict[str, tuple[int, ChartLayer]] = {
    "DEPARE": (42, ChartLayer.DEPARE),
    "DRGARE": (46, ChartLayer.DRGARE),
    "LNDARE": (71, ChartLayer.LNDARE),
    "PONTON": (95, ChartLayer.LNDARE),
    "HULKES": (65, ChartLayer.LNDARE),
    "FLODOC": (57, ChartLayer.LNDARE),
    "DRYDOC": (47, ChartLayer.LNDARE),
    "OBSTRN": (86, ChartLayer.HAZARD),
    "WRECKS": (159, ChartLayer.HAZARD),
    "UWTROC": (153, ChartLayer.HAZARD),
}


class ChannelKind(StrEnum):
    """What a routeing object of the chart is (``CHANNEL_CLASSES``)."""

    FAIRWAY = "fairway"
    DREDGED_AREA = "dredged-area"
    DEEP_WATER_ROUTE = "deep-water-route"
    TSS_LANE = "tss-lane"
    TSS_ZONE = "tss-zone"
    RECOMMENDED_TRACK = "recommended-track"
    NAVIGATION_LINE = "navigation-line"
    TSS_LINE = "tss-line"
    TSS_BOUNDARY = "tss-boundary"


# S-57 object class acronym → (numeric code, kind), areas first, then lines.
CHANNEL_CLASSES: dict[str, tuple[int, ChannelKind]] = {
    "FAIRWY": (51, ChannelKind.FAIRWAY),
    "DRGARE": (46, ChannelKind.DREDGED_AREA),
    "DWRTPT": (41, ChannelKind.DEEP_WATER_ROUTE),
    "TSSLPT": (148, ChannelKind.TSS_LANE),
    "TSEZNE": (150, ChannelKind.TSS_ZONE),
    "RECTRC": (109, ChannelKind.RECOMMENDED_TRACK),
    "NAVLNE": (85, ChannelKind.NAVIGATION_LINE),
    "TSELNE": (145, ChannelKind.TSS_LINE),
    "TSSBND": (146, ChannelKind.TSS_BOUNDARY),
}
AREA_CHANNEL_KINDS = frozenset(
    {
        ChannelKind.FAIRWAY,
        ChannelKind.DREDGED_AREA,
        ChannelKind.DEEP_WATER_ROUTE,
        ChannelKind.TSS_LANE,
        ChannelKind.TSS_ZONE,
    }
)
CHANNEL_CLASS_BY_CODE = {code: name for name, (code, _) in CHANNEL_CLASSES.items()}
ACRONYM_BY_CODE = {code: name for name, (code, _) in OBJECT_CLASSES.items()}
BLOCKING_CLASSES = [
    name
    for name, (_, role) in OBJECT_CLASSES.items()
    if role in (ChartLayer.LNDARE, ChartLayer.HAZARD)
]
POLYGONAL = (shapely.GeometryType.POLYGON, shapely.GeometryType.MULTIPOLYGON)
