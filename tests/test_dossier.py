"""The dossier of an encounter (report/dossier.py, the map's time ticks and least separation in
report/encounter_figure.py), checked against the series it is made of, on San Diego."""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
import pytest

from colregs9_cli.report.dossier import (
    TIMELINE_COLUMNS,
    TIMELINE_MOST_ROWS,
    TIMELINE_STEP_S,
    events,
    motion_figure,
    report_gap_lines,
    timeline,
    timeline_html,
    timeline_markdown,
    timeline_step_s,
)
from colregs9_cli.report.encounter_figure import (
    FIGURE_HEIGHT_IN,
    LEAST_SEPARATION_LABEL,
    LEGEND_ROWS_FITTED,
    encounter_figure,
    least_separation_positions,
    time_tick_s,
    time_ticks,
)

# TRADITION (own ship) and CHAMPAGNE: the raw reports close to about 97 m at 00:19:12.
TRADITION = "20220103T001114-338403914-367412850"


def _outcome(result, encounter_id: str):
    (outcome,) = [o for o in result.encounters if o.summary.encounter_id == encounter_id]
    return outcome


@pytest.fixture(scope="module")
def tradition(sandiego_replay):
    return _outcome(sandiego_replay, TRADITION)


def _utc(table: pd.DataFrame) -> pd.Series:
    return pd.to_datetime(table["utc"], utc=True)


def test_timeline_rows_are_series_rows_every_step_and_at_each_event(tradition) -> None:
    table, step_s = timeline(tradition)
    assert step_s == TIMELINE_STEP_S
    series = tradition.series.set_index(pd.to_datetime(tradition.series["timestamp"], utc=True))
    for row in table.itertuples(index=False):
        source = series.loc[row.utc]
        for column in TIMELINE_COLUMNS[2:]:
            assert getattr(row, column) == pytest.approx(source[column], nan_ok=True)
    elapsed_s = (_utc(table) - tradition.summary.trigger_utc).dt.total_seconds()
    plain = table["event"] == ""
    assert (elapsed_s[plain] % step_s == 0).all()
    # Every step from the trigger to the end of the series is there.
    end_s = (series.index[-1] - tradition.summary.trigger_utc).total_seconds()
    assert set(np.arange(0.0, end_s + 1e-9, step_s)) <= set(elapsed_s)
    assert _utc(table).is_monotonic_increasing


def test_timeline_marks_trigger_least_separation_and_the_pass(tradition) -> None:
    table, _ = timeline(tradition)
    s = tradition.summary
    named = dict(zip(table["event"], _utc(table), strict=True))
    assert named["trigger"] == s.trigger_utc
    (least,) = [e for e in named if e.startswith("least separation")]
    assert named[least] == s.actual_min_separation_utc == pd.Timestamp("2022-01-03 00:19:12Z")
    assert least == (
        f"least separation {s.actual_min_separation_m:.0f} m "
        f"(hull to hull {s.actual_min_separation_hull_m:.0f} m)"
    )
    assert table["event"].iloc[-1] == "passed: range opened"
    assert table["range_m"].min() == pytest.approx(s.actual_min_separation_m)


def test_each_give_way_action_is_an_event_at_its_second(sandiego_replay) -> None:
    acted = [
        o
        for o in sandiego_replay.encounters
        if o.summary.action_before_cpa_s and o.summary.actual_min_separation_utc is not None
    ]
    assert acted, "San Diego has give-way vessels that acted"
    for outcome in acted:
        s = outcome.summary
        found = {e.name: e.utc for e in events(outcome)}
        for mmsi, action, before in zip(
            s.give_way_vessels.split(";"),
            s.give_way_action.split(";"),
            s.action_before_cpa_s.split(";"),
            strict=True,
        ):
            if not before:
                continue
            who = "own ship" if mmsi == str(s.own_mmsi) else "target"
            expected = s.actual_min_separation_utc - pd.Timedelta(seconds=float(before))
            assert found[f"{who}: {action}"] == expected


def test_a_long_encounter_gets_a_longer_step() -> None:
    assert timeline_step_s(600.0) == TIMELINE_STEP_S
    assert timeline_step_s(TIMELINE_MOST_ROWS * TIMELINE_STEP_S) == 30.0
    assert timeline_step_s(3 * 3600.0) == 300.0
    for duration_s in (10.0, 1200.0, 5000.0, 20000.0):
        assert duration_s / timeline_step_s(duration_s) < TIMELINE_MOST_ROWS


def test_report_gaps_in_words(tradition) -> None:
    s = tradition.summary
    own, target = report_gap_lines(s)
    assert f"{s.own_largest_report_gap_s:.0f} s" in own
    assert f"{s.target_largest_report_gap_s:.0f} s" in target
    for line, sparse in ((own, s.own_reports_sparse), (target, s.target_reports_sparse)):
        assert ("sparse" in line) is bool(sparse)


def test_sparse_means_farther_unseen_than_the_least_separation(sandiego_replay) -> None:
    pairs = [p.summary for p in sandiego_replay.pairs if p.summary.actual_min_separation_m]
    for s in pairs:
        for vessel in ("a", "b"):
            gap_s = getattr(s, f"largest_report_gap_s_{vessel}")
            sparse = getattr(s, f"reports_sparse_{vessel}")
            assert gap_s is not None and gap_s >= 0.0
            if gap_s == 0.0:
                assert sparse is False
    # Class B yachts reporting every 30 s and more, passing within a few hundred metres.
    assert any(s.reports_sparse_a or s.reports_sparse_b for s in pairs)


def test_the_html_and_markdown_timelines_hold_every_row(tradition) -> None:
    table, _ = timeline(tradition)
    page = "\n".join(timeline_html(tradition))
    assert page.count("<tr") == len(table) + 1
    assert page.count('<tr class="event">') == (table["event"] != "").sum()
    assert "00:19:12" in page and "least separation 97 m" in page
    markdown = timeline_markdown(tradition)
    rows = [line for line in markdown if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == len(table)


def test_motion_figure_plots_range_cpa_and_the_relative_track(tradition) -> None:
    figure = motion_figure(tradition)
    left, right = figure.axes
    series = tradition.series
    lines = {line.get_label(): line for line in left.get_lines()}
    np.testing.assert_allclose(lines["range"].get_ydata(), series["range_m"])
    np.testing.assert_allclose(lines["CPA predicted"].get_ydata(), series["cpa_m"])
    relative = {line.get_label(): line for line in right.get_lines()}["target relative to own ship"]
    np.testing.assert_allclose(relative.get_xdata(), series["target_east_m"] - series["own_east_m"])
    np.testing.assert_allclose(
        relative.get_ydata(), series["target_north_m"] - series["own_north_m"]
    )
    # The closest point of the relative track is the least separation.
    distance = np.hypot(relative.get_xdata(), relative.get_ydata())
    assert distance.min() == pytest.approx(tradition.summary.actual_min_separation_m, rel=1e-6)
    figure.savefig(io.BytesIO(), format="png", dpi=40)


def test_the_map_marks_whole_minutes_and_the_least_separation(sandiego_replay, tradition) -> None:
    figure = encounter_figure(tradition, None, 0.0, sandiego_replay.frame)
    (ax,) = figure.axes
    times = tradition.own_track["timestamp"]
    tick_s = time_tick_s((times.max() - times.min()).total_seconds())
    assert tick_s == 60.0
    labels = {text.get_text() for text in ax.texts}
    for track in (tradition.own_track, tradition.target_track):
        ticks = time_ticks(track, tick_s)
        assert (pd.to_datetime(ticks["timestamp"]).dt.second == 0).all()
        shown = {f"{t:%H:%M}" for t in pd.to_datetime(ticks["timestamp"])}
        assert shown & labels
    own_at, target_at = least_separation_positions(tradition)
    (line,) = [
        line for line in ax.get_lines() if line.get_label().startswith(LEAST_SEPARATION_LABEL)
    ]
    np.testing.assert_allclose(line.get_xydata(), [own_at, target_at])
    assert np.hypot(own_at[0] - target_at[0], own_at[1] - target_at[1]) == pytest.approx(
        tradition.summary.actual_min_separation_m, rel=0.01
    )
    assert "at 00:19:12" in line.get_label()
    figure.savefig(io.BytesIO(), format="png", dpi=40)


def test_the_dossier_names_the_channel_and_rule_9a(sandiego_replay) -> None:
    from colregs9_cli.report.dossier import channel_lines

    (champagne,) = [
        o
        for o in sandiego_replay.encounters
        if o.summary.own_name == "CHAMPAGNE" and o.summary.target_name == "LETO"
    ]
    own, target = channel_lines(champagne.summary)
    s = champagne.summary
    assert own.startswith(
        f"own ship: at the trigger in San Diego Harbor Channel, along, "
        f"{s.own_channel_offset_m:.0f} m to starboard of its axis"
    )
    assert "rule 9(a), keeps to her starboard side: true" in own
    assert target.startswith("target: at the trigger in San Diego Harbor Channel, along")
    outside = [o for o in sandiego_replay.encounters if o.summary.own_name == "SAILEBRATE"]
    assert all(
        channel_lines(o.summary) == []
        for o in outside
        if o.summary.own_channel is None
        and o.summary.target_channel is None
        and o.summary.own_channel_at_min_separation is None
        and o.summary.target_channel_at_min_separation is None
    )
    (declined,) = [
        o
        for o in sandiego_replay.encounters
        if o.summary.own_name == "SHELTER ISLAND" and o.summary.rule9_clause is not None
    ]
    assert channel_lines(declined.summary)[-1] == (
        "rule 9 not applied though the estimator found a vessel restricted: she is in no "
        "charted channel"
    )


def test_a_long_legend_leaves_the_title_and_the_axis_labels_in_the_figure(sandiego_replay) -> None:
    # The San Diego chart adds the channel and its axis to the legend: the figure grows for
    # them, so that nothing is cut off or drawn over, as a reader sees it.
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from colregs9_cli.charts.water import load_chart

    from fixture_files import SANDIEGO_ENC

    (outcome,) = [
        o
        for o in sandiego_replay.encounters
        if (o.summary.own_name, o.summary.target_name) == ("WELL PLAYED", "KAYLEIGH")
    ]
    chart = load_chart([SANDIEGO_ENC], frame=sandiego_replay.frame)
    figure = encounter_figure(outcome, chart, 0.0, sandiego_replay.frame)
    renderer = FigureCanvasAgg(figure).get_renderer()
    figure.draw(renderer)
    (ax, _colourbar) = figure.axes
    (legend,) = figure.legends
    labels = [text.get_text() for text in legend.get_texts()]
    assert {"charted channel", "channel axis"} <= set(labels)
    # two columns of LEGEND_ROWS_FITTED rows fit the figure as drawn; this legend has more
    assert len(labels) > 2 * LEGEND_ROWS_FITTED
    assert figure.get_figheight() > FIGURE_HEIGHT_IN
    whole = figure.bbox
    title = ax.title.get_window_extent(renderer)
    assert whole.y0 <= title.y0 and title.y1 <= whole.y1 and title.x0 >= whole.x0
    xlabel = ax.xaxis.label.get_window_extent(renderer)
    box = legend.get_window_extent(renderer)
    assert xlabel.y0 > box.y1  # the axis label above the legend, not under it
    assert whole.y0 <= box.y0
