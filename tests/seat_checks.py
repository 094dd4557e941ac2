"""Checks shared by the replay tests: both seats of a pair tell the same story."""

from __future__ import annotations

import pandas as pd

from colregs9_cli.core.rule9 import PairVerdict


def _seat_pairs(table: pd.DataFrame) -> pd.DataFrame:
    """Each pair's two seats side by side (suffix _other for the mirrored seat)."""
    mirrored = table.merge(
        table,
        left_on=["pair_id", "own_mmsi", "target_mmsi"],
        right_on=["pair_id", "target_mmsi", "own_mmsi"],
        suffixes=("", "_other"),
    )
    return mirrored[mirrored["own_mmsi"] < mirrored["target_mmsi"]]


PAIR_LEVEL_COLUMNS = (
    "interaction",
    "interaction_basis",
    "situation",
    "situation_ambiguous",
    "situation_basis",
    "give_way_vessels",
    "deciding_rule",
    "rule9_applied",
    "both_restricted",
    "data_covers_cpa",
    "actual_min_separation_m",
    "give_way_vessel_acted",
    "give_way_action",
    "stand_on_vessel_kept_course",
    "trigger_utc",
)


def _same(left: pd.Series, right: pd.Series) -> bool:
    return bool(((left == right) | (left.isna() & right.isna())).all())


def assert_seats_agree(table: pd.DataFrame) -> int:
    """Every pair seen from both seats has one situation and one set of give-way vessels,
    and a crossing has exactly one give-way vessel. Returns the number of pairs checked."""
    pairs = _seat_pairs(table)
    for column in PAIR_LEVEL_COLUMNS:
        assert _same(pairs[column], pairs[f"{column}_other"]), column
    assert _same(pairs["own_role_final"], pairs["target_role_final_other"])
    assert _same(pairs["own_role_colregs"], pairs["target_role_colregs_other"])
    assert _same(pairs["automaton_path"], pairs["target_seat_automaton_path_other"])
    # Only an encounter has a verdict: the other interactions' verdict columns are empty.
    others = pairs[pairs["interaction"] != "encounter"]
    assert others["situation"].isna().all() and others["own_role_final"].isna().all()
    pairs = pairs[pairs["interaction"] == "encounter"]
    final_give_way = pairs["give_way_vessels"].str.split(";").str.len()
    assert (final_give_way[pairs["situation"] == "crossing"] == 1).all()
    assert (final_give_way[pairs["situation"] == "overtaking"] == 1).all()
    for row in pairs.itertuples():
        named = set(str(row.give_way_vessels).split(";"))
        by_role = {
            str(m)
            for m, role in (
                (row.own_mmsi, row.own_role_final),
                (row.target_mmsi, row.target_role_final),
            )
            if role == "give-way"
        }
        assert named == by_role
    return len(others) + len(pairs)


def swapped(verdict: PairVerdict) -> PairVerdict:
    """The same verdict with the vessels in the other order: what the other seat must get."""
    return PairVerdict(
        situation=verdict.situation,
        role_colregs=(verdict.role_colregs[1], verdict.role_colregs[0]),
        seat_a=verdict.seat_b,
        seat_b=verdict.seat_a,
        role_final=(verdict.role_final[1], verdict.role_final[0]),
        deciding_rule=verdict.deciding_rule,
        both_restricted=verdict.both_restricted,
        rule9_clause=verdict.rule9_clause,
    )
