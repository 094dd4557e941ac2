"""An encounter's dossier: what an investigator quotes (docs/design.md §5, Reports).

- ``timeline``: the encounter's series from the trigger to the passing at a fixed step (as
  accident reports print them, 10–30 s), with the events on their own rows at their own
  second: the trigger, the predicted CPA, each give-way action, the least separation, and
  where the series ends (the passing, or the end of the data).
- ``motion_figure``: range and the CPA predicted at each step against time, beside the
  relative-motion plot (the target's position relative to own ship, north up, as a radar
  plot shows it).
- ``report_gap_lines``: each vessel's longest gap between reports over the passing, and
  whether she ran farther unseen than the least separation.

The timeline's step is ``TIMELINE_STEP_S``, lengthened for long encounters so that a table
has at most ``TIMELINE_MOST_ROWS`` rows; every row is a row of the encounter's time series
CSV, which has every second.
"""

from __future__ import annotations

import html
from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..core.replay_results import EncounterOutcome
from ..core.rows import EncounterSummary
from .encounter_figure import OWN_TRACK_COLOUR, TARGET_COLOUR

TIMELINE_STEP_S = 15.0
TIMELINE_LONGER_STEPS_S = (30.0, 60.0, 120.0, 300.0, 600.0)
TIMELINE_MOST_ROWS = 80
TIME_FORMAT = "%H:%M:%S"


@dataclass(frozen=True)
class Event:
    """A moment of the encounter, named as the timeline prints it."""

    utc: pd.Timestamp
    name: str


def _give_way_actions(s: EncounterSummary) -> list[Event]:
    """Each give-way vessel's action at its second: the least separation less the time
    before it (``give_way_vessels``, ``give_way_action`` and ``action_before_cpa_s`` list the
    give-way vessels in the same order)."""
    if s.actual_min_separation_utc is None or not s.give_way_vessels:
        return []
    vessels = s.give_way_vessels.split(";")
    actions = (s.give_way_action or "").split(";")
    seconds = (s.action_before_cpa_s or "").split(";")
    events = []
    for mmsi, action, before in zip(vessels, actions, seconds, strict=False):
        if not before:
            continue
        who = "own ship" if mmsi == str(s.own_mmsi) else "target"
        utc = s.actual_min_separation_utc - pd.Timedelta(seconds=float(before))
        events.append(Event(utc, f"{who}: {action}"))
    return events


def events(outcome: EncounterOutcome) -> list[Event]:
    """The encounter's events in time order (see the module docstring); those outside the
    series (a predicted CPA past its end) are left out."""
    s = outcome.summary
    found = [Event(s.trigger_utc, "trigger")]
    predicted = (s.trigger_utc + pd.Timedelta(seconds=s.tcpa_s)).floor("s")
    found.append(Event(predicted, "CPA predicted"))
    found += _give_way_actions(s)
    if s.actual_min_separation_utc is not None and s.actual_min_separation_m is not None:
        hull = s.actual_min_separation_hull_m
        name = f"least separation {s.actual_min_separation_m:.0f} m" + (
            "" if hull is None else f" (hull to hull {hull:.0f} m)"
        )
        found.append(Event(s.actual_min_separation_utc, name))
    series = outcome.series
    if not series.empty:
        last = pd.Timestamp(series["timestamp"].iloc[-1])
        found.append(Event(last, "passed: range opened" if s.data_covers_cpa else "data end"))
        first = pd.Timestamp(series["timestamp"].iloc[0])
        found = [e for e in found if first <= e.utc <= last]
    return sorted(found, key=lambda e: e.utc)


def timeline_step_s(duration_s: float) -> float:
    """``TIMELINE_STEP_S``, or the first longer step that keeps the table short."""
    for step_s in (TIMELINE_STEP_S, *TIMELINE_LONGER_STEPS_S):
        if duration_s / step_s < TIMELINE_MOST_ROWS:
            return step_s
    return TIMELINE_LONGER_STEPS_S[-1]


TIMELINE_COLUMNS = (
    "utc",
    "event",
    "own_lat_deg",
    "own_lon_deg",
    "own_cog_deg",
    "own_heading_deg",
    "own_sog_kn",
    "target_lat_deg",
    "target_lon_deg",
    "target_cog_deg",
    "target_heading_deg",
    "target_sog_kn",
    "range_m",
    "beta_deg",
    "beta_prime_deg",
    "cpa_m",
    "tcpa_s",
)


def timeline(outcome: EncounterOutcome) -> tuple[pd.DataFrame, float]:
    """The timeline table (``TIMELINE_COLUMNS``) and its step in seconds: the series' rows
    every step from the trigger, and each event's row, in time order."""
    series = outcome.series
    if series.empty:
        return pd.DataFrame(columns=list(TIMELINE_COLUMNS)), TIMELINE_STEP_S
    utc = pd.to_datetime(series["timestamp"], utc=True)
    elapsed_s = (utc - utc.iloc[0]).dt.total_seconds().to_numpy()
    step_s = timeline_step_s(float(elapsed_s[-1]))
    on_step = np.isclose(np.mod(elapsed_s, step_s), 0.0)
    names: dict[int, list[str]] = {}
    for event in events(outcome):
        row = int(np.argmin(np.abs((utc - event.utc).dt.total_seconds().to_numpy())))
        names.setdefault(row, []).append(event.name)
    rows = sorted(set(np.flatnonzero(on_step).tolist()) | set(names))
    table = series.iloc[rows].reset_index(drop=True)
    table = table.assign(
        utc=utc.iloc[rows].to_numpy(), event=["; ".join(names.get(r, [])) for r in rows]
    )
    return table[list(TIMELINE_COLUMNS)], step_s


BEARINGS_NOTE = (
    "β: the target's bearing relative to own ship's course; β′: own ship's bearing relative "
    "to the target's course (degrees clockwise)."
)
# Column headers and how each value is written (positions to 1e-5°, about a metre).
_HEADERS = {
    "utc": "UTC",
    "event": "event",
    "own_lat_deg": "own lat",
    "own_lon_deg": "own lon",
    "own_cog_deg": "own COG°",
    "own_heading_deg": "own HDG°",
    "own_sog_kn": "own SOG kn",
    "target_lat_deg": "target lat",
    "target_lon_deg": "target lon",
    "target_cog_deg": "target COG°",
    "target_heading_deg": "target HDG°",
    "target_sog_kn": "target SOG kn",
    "range_m": "range m",
    "beta_deg": "β°",
    "beta_prime_deg": "β′°",
    "cpa_m": "CPA m",
    "tcpa_s": "TCPA s",
}
_DECIMALS = {"lat_deg": 5, "lon_deg": 5, "sog_kn": 1}


def _text(column: str, value: object) -> str:
    if column == "utc":
        return pd.Timestamp(value).strftime(TIME_FORMAT)  # type: ignore[arg-type]
    if column == "event":
        return str(value)
    number = float(value)  # type: ignore[arg-type]
    if not np.isfinite(number):
        return ""
    decimals = next((d for suffix, d in _DECIMALS.items() if column.endswith(suffix)), 0)
    return f"{round(number, decimals) + 0.0:.{decimals}f}"  # + 0.0: no "-0"


def _cells(table: pd.DataFrame) -> list[list[str]]:
    return [
        [_text(column, value) for column, value in zip(TIMELINE_COLUMNS, row, strict=True)]
        for row in table.itertuples(index=False)
    ]


def _step_text(step_s: float) -> str:
    return f"{step_s:g} s" if step_s < 60 else f"{step_s / 60:g} min"


def _place_text(channel: str | None, relation: str | None, offset_m: float | None) -> str:
    if channel is None:
        return "in no charted channel"
    text = f"in {channel}, {relation}"  # a StrEnum: its value
    if offset_m is not None:
        side = "starboard" if offset_m > 0 else "port"
        text += f", {abs(offset_m):.0f} m to {side} of its axis"
    return text


def channel_lines(s: EncounterSummary) -> list[str]:
    """Where each vessel was in the charted channels, rule 9(a) for each, and the clause of
    rule 9 that decided; nothing where no vessel was in a channel and rule 9 did not decide."""
    lines = []
    for who, title in (("own", "own ship"), ("target", "target")):
        at_trigger = _place_text(
            getattr(s, f"{who}_channel"),
            getattr(s, f"{who}_channel_relation"),
            getattr(s, f"{who}_channel_offset_m"),
        )
        at_least = _place_text(
            getattr(s, f"{who}_channel_at_min_separation"),
            getattr(s, f"{who}_channel_relation_at_min_separation"),
            getattr(s, f"{who}_channel_offset_m_at_min_separation"),
        )
        if at_trigger == at_least == "in no charted channel":
            continue
        line = f"{title}: at the trigger {at_trigger}; at the least separation {at_least}"
        fact = getattr(s, f"{who}_keeps_to_starboard_side")
        if fact is not None:
            basis = getattr(s, f"{who}_keeps_to_starboard_side_basis")
            line += f"; rule 9(a), keeps to her starboard side: {fact.value} ({basis})"
        confined = getattr(s, f"{who}_confined_to_channel")
        if confined is not None:
            basis = getattr(s, f"{who}_confined_to_channel_basis")
            line += f"; confined to the channel by her draught: {confined.value} ({basis})"
        lines.append(line)
    if s.rule9_clause is not None and s.rule9_applied:
        lines.append(f"rule 9 decided under clause {s.rule9_clause.value}")
    elif s.rule9_clause is not None:
        why = (
            "the estimator found a vessel restricted: she is in no charted channel"
            if s.rule9_clause.value == "estimator"
            else "a vessel was found restricted: no clause of rule 9(b)-(d) binds the other vessel"
        )
        lines.append(f"rule 9 not applied though {why}")
    return lines


def _gap_text(s: EncounterSummary, who: str, title: str) -> str:
    gap_s = getattr(s, f"{who}_largest_report_gap_s")
    if gap_s is None:
        return f"{title}: no reports in the window"
    sparse = getattr(s, f"{who}_reports_sparse")
    note = (
        ": sparse, she ran farther between two reports than the least separation, so her "
        "track near it is interpolated, not seen"
        if sparse
        else ""
    )
    return f"{title}'s longest gap between reports {gap_s:.0f} s{note}"


def report_gap_lines(s: EncounterSummary) -> list[str]:
    """Both vessels' longest report gaps over the passing, in words."""
    return [_gap_text(s, "own", "own ship"), _gap_text(s, "target", "target")]


def timeline_html(outcome: EncounterOutcome) -> list[str]:
    """The timeline as an HTML table, with the events' rows marked, after a line on each
    vessel's report gaps."""
    table, step_s = timeline(outcome)
    lines = [
        f"<h4>Timeline (every {_step_text(step_s)} from the trigger, and at each event)</h4>",
        f"<p>{html.escape(BEARINGS_NOTE)}</p>",
        '<ul class="gaps">',
        *(
            f"<li>{html.escape(line)}</li>"
            for line in channel_lines(outcome.summary) + report_gap_lines(outcome.summary)
        ),
        "</ul>",
        '<div class="timeline"><table class="timeline"><thead><tr>',
        "".join(f"<th>{html.escape(_HEADERS[c])}</th>" for c in TIMELINE_COLUMNS),
        "</tr></thead><tbody>",
    ]
    for cells in _cells(table):
        marked = ' class="event"' if cells[1] else ""
        lines.append(
            f"<tr{marked}>"
            + "".join(
                f"<td{'' if i < 2 else ' class=num'}>{html.escape(text)}</td>"
                for i, text in enumerate(cells)
            )
            + "</tr>"
        )
    lines.append("</tbody></table></div>")
    return lines


def timeline_markdown(outcome: EncounterOutcome) -> list[str]:
    """The timeline as a Markdown table, after the report gap lines."""
    table, step_s = timeline(outcome)
    lines = [
        f"Timeline, every {_step_text(step_s)} from the trigger and at each event. {BEARINGS_NOTE}",
        "",
        *(
            f"- {line}"
            for line in channel_lines(outcome.summary) + report_gap_lines(outcome.summary)
        ),
        "",
        "| " + " | ".join(_HEADERS[c] for c in TIMELINE_COLUMNS) + " |",
        "|" + "|".join(":--" if i < 2 else "--:" for i in range(len(TIMELINE_COLUMNS))) + "|",
    ]
    for cells in _cells(table):
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def motion_figure(outcome: EncounterOutcome) -> Figure:
    """Range and predicted CPA against time (left), and the relative-motion plot (right):
    the target's position relative to own ship, north up, in metres, with the events
    marked on both."""
    series = outcome.series
    s = outcome.summary
    figure = Figure(figsize=(11.0, 4.6), layout="constrained")
    left, right = figure.subplots(1, 2, width_ratios=(1.35, 1.0))
    utc = pd.to_datetime(series["timestamp"], utc=True)
    minutes = ((utc - s.trigger_utc).dt.total_seconds() / 60.0).to_numpy()
    left.plot(minutes, series["range_m"], color="tab:blue", label="range")
    left.plot(minutes, series["cpa_m"], color="tab:purple", ls="--", label="CPA predicted")
    left.set_xlabel(f"minutes from the trigger ({s.trigger_utc:%H:%M:%S} UTC)")
    left.set_ylabel("metres")
    left.set_ylim(bottom=0.0)
    left.grid(True, alpha=0.3)
    north = (series["target_north_m"] - series["own_north_m"]).to_numpy(dtype=float)
    east = (series["target_east_m"] - series["own_east_m"]).to_numpy(dtype=float)
    right.plot(east, north, color=TARGET_COLOUR, lw=1.2, label="target relative to own ship")
    right.plot([0.0], [0.0], marker="^", color=OWN_TRACK_COLOUR, ms=9, ls="", label="own ship")
    # The relative motion line the trigger predicted: from the target's relative position then
    # to where constant velocities put her at TCPA.
    (own_north, own_east), (target_north, target_east) = (
        outcome.own_at_tcpa_m,
        outcome.target_at_tcpa_m,
    )
    if len(north):
        right.plot(
            [east[0], target_east - own_east],
            [north[0], target_north - own_north],
            color="grey",
            ls="--",
            lw=0.9,
            label="predicted at the trigger",
        )
    for event in events(outcome):
        row = int(np.argmin(np.abs((utc - event.utc).dt.total_seconds().to_numpy())))
        colour = "tab:red" if event.name.startswith("least") else "tab:green"
        colour = "grey" if event.name in ("trigger", "CPA predicted") else colour
        left.axvline(minutes[row], color=colour, lw=0.8, alpha=0.7)
        left.annotate(
            event.name,
            (minutes[row], 1.0),
            xycoords=("data", "axes fraction"),
            rotation=90,
            va="top",
            ha="right",
            fontsize="x-small",
            color=colour,
        )
        right.plot(east[row], north[row], "o", color=colour, ms=5)
        right.annotate(event.name, (east[row], north[row]), fontsize="x-small", color=colour)
    if s.actual_min_separation_m is not None:
        circle = np.linspace(0.0, 2.0 * np.pi, 181)
        radius = s.actual_min_separation_m
        right.plot(radius * np.sin(circle), radius * np.cos(circle), color="tab:red", lw=0.6)
    right.set_aspect("equal", adjustable="datalim")
    right.set_xlabel("east of own ship (m)")
    right.set_ylabel("north of own ship (m)")
    right.grid(True, alpha=0.3)
    left.legend(fontsize="small", loc="lower left")
    right.legend(fontsize="small", loc="best")
    figure.suptitle(f"{s.encounter_id}: range, CPA and relative motion", fontsize="medium")
    return figure
