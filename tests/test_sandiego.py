"""A real audit end to end: real MarineCadastre AIS in San Diego Bay over the real NOAA ENC
US5CA72M (with its update files), so that the estimator runs on real depths."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from fixture_files import SANDIEGO_AIS
from seat_checks import assert_seats_agree

TRIGGERED_SEATS = 38  # 19 pairs, each from both seats


@pytest.fixture(scope="module")
def sandiego(sandiego_replay):
    return sandiego_replay


def _table(result, name: str) -> pd.DataFrame:
    return pd.read_csv(result.out_dir / name, dtype=str, keep_default_na=False)


def test_every_pair_has_one_situation_and_one_set_of_give_way_vessels(sandiego) -> None:
    encounters = pd.read_csv(
        sandiego.out_dir / "encounters.csv",
        dtype={"give_way_vessels": str, "deciding_rule": str, "give_way_action": str},
    )
    assert len(encounters) == TRIGGERED_SEATS
    assert assert_seats_agree(encounters) == TRIGGERED_SEATS // 2
    pairs = _table(sandiego, "pairs.csv")
    assert len(pairs) == TRIGGERED_SEATS // 2
    crossing = pairs[pairs["situation"] == "crossing"]
    assert len(crossing) > 0
    assert (crossing["give_way_vessels"].str.count(";") == 0).all()


def test_the_estimator_runs_on_real_depths(sandiego) -> None:
    pairs = _table(sandiego, "pairs.csv")
    estimates = pd.concat([pairs["estimated_restricted_a"], pairs["estimated_restricted_b"]])
    # real depth areas: some vessels are restricted, others have room
    assert {"true", "false"} <= set(estimates)
    # Class B craft report no draught: every verdict that used such an estimate says so
    assert (pairs["verdict_rests_on_defaults"] == "true").sum() > 0
    defaulted = (pairs["defaulted_dimensions_a"] != "") | (pairs["defaulted_dimensions_b"] != "")
    assert (
        pairs.loc[pairs["verdict_rests_on_defaults"] == "true"].index.isin(pairs[defaulted].index)
    ).all()
    manifest = json.loads((sandiego.out_dir / "run.json").read_text(encoding="utf-8"))
    assert manifest["verdicts"]["pairs"] == TRIGGERED_SEATS // 2
    assert manifest["ledger_balanced"]


def test_small_craft_take_small_craft_dimensions(sandiego) -> None:
    encounters = _table(sandiego, "encounters.csv")
    source = pd.read_csv(SANDIEGO_AIS)
    class_b = set(source.loc[source["TransceiverClass"] == "B", "MMSI"].astype(str))
    no_draught = encounters[encounters["target_dimensions_defaulted"].str.contains("draught")]
    small = no_draught[no_draught["target_mmsi"].isin(class_b)]
    assert len(small) > 0
    # a Class B pleasure or sailing craft never gets the 3.2 m of a Class A merchant vessel
    assert (small["target_draught_m"].astype(float) <= 2.0).all()
    class_a = no_draught[~no_draught["target_mmsi"].isin(class_b)]
    assert (class_a["target_draught_m"].astype(float) >= 3.0).all()


def test_no_audit_fact_on_data_that_stops(sandiego) -> None:
    pairs = _table(sandiego, "pairs.csv")
    stops = pairs["data_covers_cpa"] == "false"
    # the least range seen so far is reported, never below the range the data end with
    seen = pairs.loc[stops, "actual_min_separation_m"].astype(float)
    assert (seen <= pairs.loc[stops, "range_m_at_trigger"].astype(float) + 1e-6).all()
    for column in ("give_way_vessel_acted", "stand_on_vessel_kept_course"):
        assert set(pairs.loc[stops, column]) <= {"insufficient-data", ""}, column
    covered = pairs[~stops]
    assert (covered["actual_min_separation_m"].astype(float) > 0).all()


def test_report_geopackage_opens_with_every_layer(sandiego) -> None:
    import numpy as np
    import pyogrio
    import shapely

    path = sandiego.out_dir / "report.gpkg"
    layers = {str(name) for name, kind in pyogrio.list_layers(path) if kind}
    assert layers == {
        "encounters",
        "tracks",
        "cpa",
        "domains",
        "navigable_water",
        "vessel_tracks",
        "lone_reports",
        "channels",
        "channel_axes",
    }
    # the QGIS styles, an attribute table beside them
    assert {str(name) for name, kind in pyogrio.list_layers(path) if not kind} == {"layer_styles"}
    for layer in layers:
        info = pyogrio.read_info(path, layer=layer)
        assert info["crs"] == "EPSG:4326" and info["features"] > 0, layer
    # one point per vessel and encounter row, at the trigger positions of encounters.csv
    meta, _, wkb, fields = pyogrio.raw.read(path, layer="encounters")
    columns = dict(zip(meta["fields"], fields, strict=True))
    assert len(wkb) == 2 * TRIGGERED_SEATS
    assert set(meta["fields"]) >= set(_table(sandiego, "encounters.csv").columns)
    points = shapely.from_wkb(wkb)
    own = np.asarray(columns["vessel"]) == "own"
    np.testing.assert_allclose(
        shapely.get_y(points[own]),
        np.asarray(columns["own_lat_deg_at_trigger"])[own].astype(float),
        atol=1e-7,
    )
    domains = pyogrio.read_info(path, layer="domains")
    assert {"restricted", "covered", "arc", "step"} <= set(domains["fields"])


def test_report_geopackage_domains_are_typed_and_every_layer_is_styled(sandiego) -> None:
    import sqlite3
    import xml.etree.ElementTree as ET

    import pyogrio

    path = sandiego.out_dir / "report.gpkg"
    meta, _, _, fields = pyogrio.raw.read(path, layer="domains")
    columns = dict(zip(meta["fields"], fields, strict=True))
    dtypes = dict(zip(meta["fields"], meta["dtypes"], strict=True))
    assert dtypes["restricted"] == dtypes["covered"] == "bool"
    state = columns["state"]
    assert set(state) <= {"restricted", "clear", "unknown"}
    assert ((state == "restricted") == (columns["restricted"] & columns["covered"])).all()
    assert ((state == "unknown") == ~columns["covered"]).all()
    with sqlite3.connect(path) as db:
        styles = db.execute(
            "SELECT f_table_name, f_geometry_column, styleQML, useAsDefault FROM layer_styles"
        ).fetchall()
    layers = {str(name) for name, kind in pyogrio.list_layers(path) if kind}
    assert {name for name, *_ in styles} == layers
    for name, geometry_column, qml, default in styles:
        assert default == 1 and geometry_column == "geom"
        renderer = ET.fromstring(qml.split("'SYSTEM'>", 1)[1]).find("renderer-v2")
        attribute = renderer.get("attr")
        if attribute is None:
            continue
        # every value the layer holds has a category, so nothing is drawn unstyled
        _, _, _, values = pyogrio.raw.read(path, layer=name, columns=[attribute])
        categories = {c.get("value") for c in renderer.iter("category")}
        assert set(map(str, values[0])) <= categories, name


def test_a_chart_far_from_the_ais_is_left_out_and_changes_nothing(
    sandiego, tmp_path_factory: pytest.TempPathFactory
) -> None:
    from colregs9_cli.jobs.replay import run_replay

    from fixture_files import ROOT, SANDIEGO_ENC

    annapolis = ROOT / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"
    out = tmp_path_factory.mktemp("sandiego_and_annapolis")
    both = run_replay(
        [SANDIEGO_AIS], chart_paths=[SANDIEGO_ENC, annapolis], out_dir=out, plots=False
    )
    charts = json.loads((out / "run.json").read_text())["charts"]
    assert [(c["path"], c["used"]) for c in charts] == [
        (str(SANDIEGO_ENC), True),
        (str(annapolis), False),
    ]
    assert both.frame == sandiego.frame  # centred on the San Diego cell, not over Kansas
    pd.testing.assert_frame_equal(
        _table(both, "encounters.csv"), _table(sandiego, "encounters.csv")
    )


def test_tradition_and_champagne_come_within_a_hundred_metres(sandiego) -> None:
    """They turned away at 1,068 m (TCPA negative: the old pass), then closed to about 97 m
    at about 00:19:12 in their raw reports: the passing runs to the real closest approach."""
    pairs = _table(sandiego, "pairs.csv").set_index(["mmsi_a", "mmsi_b"])
    pair = pairs.loc[("338403914", "367412850")]
    assert pair["interaction"] == "encounter" and pair["data_covers_cpa"] == "true"
    antenna_m = float(pair["actual_min_separation_m"])
    assert 90.0 < antenna_m < 105.0
    assert pair["actual_min_separation_utc"].startswith("2022-01-03T00:19:")
    assert float(pair["actual_min_separation_hull_m"]) <= antenna_m
