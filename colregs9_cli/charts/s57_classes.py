"""The S-57 object classes a chart is read for, and the role each plays in it.

Object classes used: DEPARE and DRGARE (dredged areas count as depth areas), LNDARE (land),
PONTON, HULKES, FLODOC and DRYDOC areas (structures that cut holes in the depth areas; they
are treated like land), and OBSTRN, WRECKS and UWTROC as point hazards.

One table (``_OBJECT_CLASSES``) serves the reader (``read``), which keeps the features of
these classes only, and the chart (``sources``, ``water``), which sorts them by role into
depth areas, land and hazards: a class is added in one place.
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
_OBJECT_CLASSES: dict[str, tuple[int, ChartLayer]] = {
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
_ACRONYM_BY_CODE = {code: name for name, (code, _) in _OBJECT_CLASSES.items()}
_BLOCKING_CLASSES = [
    name
    for name, (_, role) in _OBJECT_CLASSES.items()
    if role in (ChartLayer.LNDARE, ChartLayer.HAZARD)
]
_POLYGONAL = (shapely.GeometryType.POLYGON, shapely.GeometryType.MULTIPOLYGON)
