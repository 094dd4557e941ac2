"""Paths of the repository's fixture files that several test modules read."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = ROOT / "fixtures"
AIS_FIXTURES = FIXTURES / "ais"
DMA26 = AIS_FIXTURES / "aisdk_2024-09-09_sample.csv"
DMA22 = AIS_FIXTURES / "aisdk_2018-06-01_sample_22col.csv"
MARINECADASTRE = AIS_FIXTURES / "marinecadastre_2023-01-11_sample.csv"
NMEA = AIS_FIXTURES / "dma_nmea_2013-11-12_5min.txt.gz"
# The demo's inputs are package data, so that `colregs9 demo` runs after a plain install.
DEMO_DATA = ROOT / "colregs9_cli" / "data" / "demo"
SCENARIOS = DEMO_DATA
MODELLED_CHART = DEMO_DATA / "aalborg_modelled.geojson"
GREENHOPPER_QUERY = DEMO_DATA / "greenhopper.toml"
SANDIEGO_AIS = ROOT / "fixtures" / "sandiego" / "marinecadastre_2022-01-03_sandiego_bay.csv"
SANDIEGO_ENC = ROOT / "fixtures" / "sandiego" / "US5CA72M.000"


def pair_summary(result, a: int, b: int):
    """The summary of the pair of vessels ``a`` and ``b`` in a replay's result (either order)."""
    (summary,) = (p.summary for p in result.pairs if {p.summary.mmsi_a, p.summary.mmsi_b} == {a, b})
    return summary
