"""The US MarineCadastre AIS CSV layouts, read through their built-in column maps
(column_map.py, mapped.py).

- ``marinecadastre`` (2018-2024): ``MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,
  IMO,CallSign,VesselType,Status,Length,Width,Draft,Cargo,TransceiverClass``;
- ``marinecadastre2015`` (2015-2017): the same without ``TransceiverClass``. MarineCadastre
  publishes vessel reports only (no base stations or AtoN), so every row is read as a
  vessel, of unknown class: ``mobile_type`` is null, and a query's ``mobile_types`` filter
  leaves such rows out;
- ``marinecadastre2025`` (2025 on, often ``.csv.zst``): ``mmsi,base_date_time,longitude,
  latitude,sog,cog,heading,vessel_name,imo,call_sign,vessel_type,status,length,width,draft,
  cargo,transceiver``, longitude before latitude.

``BaseDateTime`` is ISO 8601 (``T`` or a space), UTC unless it names a zone
(``mapped.iso_milliseconds``). The numeric
``VesselType`` (ITU-R M.1371) maps to the DMA ship type texts (``ship_type_text``);
``Status`` is already the ITU code (0-15, anything else null); the transceiver class A/B
becomes the mobile type ``Class A``/``Class B``. ``IMO`` is written ``IMO9307839``. Length
and breadth are the ``Length`` and ``Width`` columns (these layouts have no A, B, C, D).
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from .clean import SHIP_TYPE_CATEGORIES

_OTHER = "Other"


def ship_type_text(codes: np.ndarray) -> pa.Array:
    """Numeric ship types to the DMA category texts (0 and NaN: null)."""
    distinct, inverse = np.unique(np.asarray(codes, dtype=np.float64), return_inverse=True)
    texts = [
        None if not np.isfinite(code) or code == 0 else SHIP_TYPE_CATEGORIES.get(int(code), _OTHER)
        for code in distinct
    ]
    return pa.array(texts, pa.string()).take(pa.array(inverse.ravel(), pa.int64()))
