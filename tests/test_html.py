"""The HTML reports as a person sees them: Playwright drives the system's Chromium at a
desktop viewport (1400 × 1000), scrolls each page to its end step by step, and checks that
every figure loaded and was shown in the window, that the page logged no error, and that
every local link resolves (a file beside the page, or an element of the page). The pages:
the San Diego replay on its ENC, the demo's two scenarios, and the stats.

The browser tests skip, with the reason, when Playwright or Chromium is missing; with
``COLREGS9_REQUIRE_BROWSER=1`` (``.ci/run``) a missing browser fails them instead.
``COLREGS9_CHROMIUM`` names the browser to drive (default: ``chromium`` on the PATH).
"""

from __future__ import annotations

import dataclasses
import os
import re
import shutil
import subprocess
import sys
from collections.abc import Iterator
from html.parser import HTMLParser
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn
from urllib.parse import unquote, urljoin, urlsplit
from urllib.request import url2pathname

import pytest

from colregs9_cli.charts.water import load_chart
from colregs9_cli.core.colregs import Role
from colregs9_cli.core.rows import situation_or_interaction
from colregs9_cli.jobs.demo import run_demo
from colregs9_cli.jobs.stats import run_stats
from colregs9_cli.progress import progress_bar
from colregs9_cli.report.html_report import (
    ENCOUNTER_TABLE_COLUMNS,
    KEY_COLUMNS,
    MORE_COLUMNS,
    _encounter_row,
    page_title,
    pair_numbers,
    time_span,
)
from colregs9_cli.report.replay_report import ENCOUNTER_DIR, write_replay_reports
from colregs9_cli.report.stats_report import HISTOGRAM_NAME

from fixture_files import DMA26, SANDIEGO_AIS, SANDIEGO_ENC

if TYPE_CHECKING:
    from playwright.sync_api import Browser, Page, ViewportSize

REQUIRE_BROWSER = "COLREGS9_REQUIRE_BROWSER"
CHROMIUM = "COLREGS9_CHROMIUM"
# A desktop window: the size at which the issue saw the figures replaced by notes.
VIEWPORT: ViewportSize = {"width": 1400, "height": 1000}
# Each step scrolls this share of the window, so that consecutive views overlap and every
# point of the page is in the window at some step.
SCROLL_SHARE = 0.8
# How long a figure in the window may take to load from the disk.
LOAD_TIMEOUT_MS = 15_000


def _no_browser(reason: str) -> NoReturn:
    if os.environ.get(REQUIRE_BROWSER) == "1":
        pytest.fail(f"{reason} ({REQUIRE_BROWSER}=1: the browser tests must run)")
    pytest.skip(reason)


def chromium_path() -> str | None:
    """The Chromium to drive: ``$COLREGS9_CHROMIUM`` when set (a path or a command name),
    else ``chromium`` (Debian) or ``chromium-browser`` on the PATH."""
    given = os.environ.get(CHROMIUM)
    if given is not None:
        return shutil.which(given)
    return shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="session")
def browser() -> Iterator[Browser]:
    """The system's Chromium under Playwright (no ``playwright install``: its driver comes
    with the wheel, the browser is the distribution's)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _no_browser("the browser tests need Playwright: pip install -e '.[test]'")
    executable = chromium_path()
    if executable is None:
        where = (
            f"{CHROMIUM}={os.environ[CHROMIUM]} is not one"
            if CHROMIUM in os.environ
            else "none is on the PATH"
        )
        _no_browser(f"the browser tests need Chromium and {where}: apt-get install chromium")
    with sync_playwright() as playwright:
        launched = playwright.chromium.launch(executable_path=executable)
        yield launched
        launched.close()


@dataclasses.dataclass
class Seen:
    """What a person saw of a page, scrolled to its end step by step."""

    figures: int  # <img> elements at the end
    shown: set[str]  # src of each image seen loaded and on top in the window
    not_loaded: set[str]  # src of each image seen in the window but not loaded
    missing_notes: list[str]  # the page's "figure not found" notes
    console_errors: list[str]
    dead_links: list[str]  # local href/src that name no file, or no element of the page
    remote: list[str]  # requests for anything but local files


# Every image that has a part in the window: its src, whether it loaded, and whether it is on
# top at the centre of its part in the window (not hidden, nor covered).
_IMAGES_IN_WINDOW = """() => Array.from(document.images).flatMap(img => {
  const box = img.getBoundingClientRect();
  const left = Math.max(box.left, 0), right = Math.min(box.right, innerWidth);
  const top = Math.max(box.top, 0), bottom = Math.min(box.bottom, innerHeight);
  if (right <= left || bottom <= top) return [];
  const hit = document.elementFromPoint((left + right) / 2, (top + bottom) / 2);
  return [{src: img.getAttribute("src"), loaded: img.complete && img.naturalWidth > 0,
           onTop: hit === img}];
})"""
# Waits until every image that reaches into the window (a lazy one not loaded yet may have
# no height) has finished loading or failing.
_WINDOW_SETTLED = """() => Array.from(document.images).every(img => {
  const box = img.getBoundingClientRect();
  return img.complete || box.bottom < 0 || box.top > innerHeight;
})"""
_AT_END = "() => Math.ceil(scrollY + innerHeight) >= document.documentElement.scrollHeight"


def open_page(browser: Browser, path: Path, suffix: str = "") -> tuple[Page, dict[str, list]]:
    """``path`` (with a query or fragment ``suffix``) in a fresh window, after its load
    event; the second item collects console errors and remote requests as they come."""
    page = browser.new_context(viewport=VIEWPORT).new_page()
    log: dict[str, list] = {"errors": [], "remote": []}
    page.on(
        "console",
        lambda message: log["errors"].append(message.text) if message.type == "error" else None,
    )
    page.on("pageerror", lambda error: log["errors"].append(str(error)))
    page.on(
        "request",
        lambda request: (
            None
            if urlsplit(request.url).scheme in ("file", "data", "about")
            else log["remote"].append(request.url)
        ),
    )
    page.goto(path.as_uri() + suffix, wait_until="load")
    return page, log


def _settle(page: Page) -> None:
    page.wait_for_function(_WINDOW_SETTLED, timeout=LOAD_TIMEOUT_MS)


class _Links(HTMLParser):
    """The href, src and xlink:href values of a page as written, and its element ids."""

    def __init__(self) -> None:
        super().__init__()
        self.targets: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name == "id" and value:
                self.ids.add(value)
            elif name in ("href", "src", "xlink:href") and value is not None:
                self.targets.append(value)


def dead_links(path: Path) -> list[str]:
    """The page's local links that name no file, or (``#id``) no element of the page: read
    from the file, so that a figure the page's script replaced is still checked."""
    links = _Links()
    links.feed(path.read_text(encoding="utf-8"))
    dead = []
    for value in links.targets:
        parts = urlsplit(urljoin(path.as_uri(), value))
        if value.startswith("#"):
            if value[1:] not in links.ids:
                dead.append(value)
        elif parts.scheme == "file" and not Path(url2pathname(unquote(parts.path))).exists():
            dead.append(value)
    return dead


def see(browser: Browser, path: Path) -> Seen:
    """Open ``path``, scroll it to its end step by step as a person would, and note at each
    step which images are in the window, loaded and on top."""
    page, log = open_page(browser, path)
    shown: set[str] = set()
    not_loaded: set[str] = set()
    while True:
        _settle(page)
        for image in page.evaluate(_IMAGES_IN_WINDOW):
            (shown if image["loaded"] and image["onTop"] else not_loaded).add(image["src"])
        if page.evaluate(_AT_END):
            break
        # The window scrolled, not the wheel: a wheel over a scrolling box (a wide table)
        # scrolls the box; lazy figures load by where the window is, however it got there.
        step = SCROLL_SHARE * VIEWPORT["height"]
        page.evaluate(f"window.scrollBy({{top: {step}, behavior: 'instant'}})")
    # A figure loaded at a later step is not "not loaded".
    seen = Seen(
        figures=page.evaluate("document.images.length"),
        shown=shown,
        not_loaded=not_loaded - shown,
        missing_notes=page.locator(".missing").all_inner_texts(),
        console_errors=log["errors"],
        dead_links=dead_links(path),
        remote=log["remote"],
    )
    # The assertion, on every image of the page at the end: complete and not empty.
    assert page.evaluate(
        "Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)"
    ), f"{path}: an image did not load"
    page.context.close()
    return seen


def assert_all_shown(seen: Seen, figures: int) -> None:
    assert seen.figures == figures
    assert len(seen.shown) == figures, sorted(seen.not_loaded)
    assert not seen.not_loaded
    assert seen.missing_notes == []
    assert seen.console_errors == []
    assert seen.dead_links == []
    assert seen.remote == []


@pytest.fixture(scope="session")
def sandiego_report(sandiego_replay, tmp_path_factory: pytest.TempPathFactory):
    """The San Diego replay (conftest's, on its ENC) written again with its figures, into a
    directory of its own: the report a user gets from ``colregs9 replay --chart``."""
    out = tmp_path_factory.mktemp("sandiego-html") / "report"
    result = dataclasses.replace(sandiego_replay, out_dir=out)
    chart = load_chart([SANDIEGO_ENC], result.frame)
    with progress_bar("figures", None, enabled=False) as silent:
        write_replay_reports(result, chart, plots=True, progress=silent)
    return result, out


@pytest.fixture(scope="session")
def demo_report(tmp_path_factory: pytest.TempPathFactory):
    return run_demo(out_dir=tmp_path_factory.mktemp("demo-html") / "demo")


@pytest.fixture(scope="session")
def stats_report(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("stats-html") / "stats"
    return run_stats([DMA26], out_dir=out), out


def test_the_sandiego_page_shows_every_figure_scrolled_through(browser, sandiego_report) -> None:
    result, out = sandiego_report
    # Per encounter: its map, and its range and relative motion.
    figures = 2 * len(result.encounters)
    assert figures == len(list((out / ENCOUNTER_DIR).glob("*.png"))) == 2 * 38
    assert_all_shown(see(browser, out / "index.html"), figures)


def test_every_encounter_has_its_timeline_on_the_page(browser, sandiego_report) -> None:
    """A timeline per encounter (and so per triggered pair), each seen in the window when its
    section is scrolled to, with the trigger and the least separation marked."""
    result, out = sandiego_report
    page, log = open_page(browser, out / "index.html")
    pairs_with_a_timeline = set()
    for outcome in result.encounters:
        s = outcome.summary
        table = page.locator(f'section[id="enc-{s.encounter_id}"] table.timeline')
        table.scroll_into_view_if_needed()
        assert table.is_visible()
        # The whole width in the window: no column behind a scroll bar.
        assert table.evaluate("t => t.getBoundingClientRect().right <= window.innerWidth")
        events = table.locator("tr.event").all_inner_texts()
        assert any("trigger" in row for row in events)
        if s.actual_min_separation_m is not None:
            assert any(f"least separation {s.actual_min_separation_m:.0f} m" in r for r in events)
        pairs_with_a_timeline.add(s.pair_id)
    assert pairs_with_a_timeline == {p.summary.pair_id for p in result.pairs}
    assert log["errors"] == []
    page.context.close()


def test_each_demo_page_shows_its_figures(browser, demo_report) -> None:
    pages = sorted(demo_report.out_dir.glob("*/index.html"))
    assert [p.parent.name for p in pages] == sorted(v.scenario for v in demo_report.verdicts)
    for verdict in demo_report.verdicts:
        figures = 2 * len(verdict.replay.encounters)
        assert figures >= 2
        assert_all_shown(see(browser, verdict.replay.out_dir / "index.html"), figures)


def test_the_stats_page_shows_its_table_and_histogram(browser, stats_report) -> None:
    run, out = stats_report
    assert_all_shown(see(browser, out / "index.html"), 1)
    page, _ = open_page(browser, out / "index.html")
    assert page.locator("table.sortable tbody tr").count() == len(run.result.to_frame()) == 3
    page.context.close()


def test_a_figure_is_shown_when_its_link_in_the_table_is_followed(browser, sandiego_report):
    """Straight from the top to the last encounter, by its link in the table: its figure
    (far below the fold at the load event) loads and is shown."""
    result, out = sandiego_report
    last = result.encounters[-1].summary.encounter_id
    page, log = open_page(browser, out / "index.html")
    page.locator(f'#encounters a[href="#enc-{last}"]').click()
    assert page.evaluate("location.hash") == f"#enc-{last}"
    figure = page.locator(f'section[id="enc-{last}"] img.figure').first
    # No scrolling but the link's: the figure is in the window where the link leads.
    _settle(page)
    assert figure.evaluate("img => img.complete && img.naturalWidth > 0")
    assert figure.is_visible()
    assert {image["src"] for image in page.evaluate(_IMAGES_IN_WINDOW) if image["onTop"]} >= {
        f"{ENCOUNTER_DIR}/{last}.png"
    }
    assert page.locator(".missing").count() == 0
    assert log["errors"] == []
    page.context.close()


def test_a_missing_figure_is_marked_on_its_own_error(browser, sandiego_report, tmp_path):
    """The last figure (below the fold) removed: only it is marked, when the browser fails
    to load it; every other figure is shown."""
    result, out = sandiego_report
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    last = f"{ENCOUNTER_DIR}/{result.encounters[-1].summary.encounter_id}.png"
    (copy / last).unlink()
    # At the load event nothing is marked yet: the lazy figure has not been asked for.
    page, _ = open_page(browser, copy / "index.html")
    assert page.locator(".missing").count() == 0
    assert page.locator("img.figure").count() == 2 * len(result.encounters)
    page.context.close()
    seen = see(browser, copy / "index.html")
    assert seen.missing_notes == [f"figure not found: {last}"]
    assert seen.figures == 2 * len(result.encounters) - 1
    assert len(seen.shown) == seen.figures and not seen.not_loaded
    assert seen.dead_links == [last]
    # Chromium logs the file it could not read; nothing else.
    assert len(seen.console_errors) == 1 and "ERR_FILE_NOT_FOUND" in seen.console_errors[0]


def test_a_missing_histogram_is_marked_though_it_fails_before_the_page_is_parsed(
    browser, stats_report, tmp_path
):
    """The stats' histogram is not lazy: its file fails while the page is still read, before
    DOMContentLoaded; the listener, set in the head, marks it all the same."""
    _, out = stats_report
    copy = tmp_path / "stats"
    shutil.copytree(out, copy)
    (copy / HISTOGRAM_NAME).unlink()
    seen = see(browser, copy / "index.html")
    assert seen.missing_notes == [f"figure not found: {HISTOGRAM_NAME}"]
    assert seen.figures == 0
    assert seen.dead_links == [HISTOGRAM_NAME]


def _column(page: Page, column: str, shown_only: bool = True) -> list[str]:
    """One column's cells in the table's order as rendered (the shown rows only)."""
    index = ENCOUNTER_TABLE_COLUMNS.index(column)
    rows = "#encounters tbody tr" + (":not(.hidden)" if shown_only else "")
    return page.locator(rows).evaluate_all(
        f"rows => rows.map(row => row.cells[{index}].textContent)"
    )


def _shown_count(page: Page) -> int:
    return int(page.locator("#encounters-shown").inner_text())


def test_the_table_filters_and_sorts_from_a_link(browser, sandiego_report) -> None:
    result, out = sandiego_report
    head_on = sum(situation_or_interaction(o.summary) == "head-on" for o in result.encounters)
    assert 0 < head_on < len(result.encounters)
    sort = ENCOUNTER_TABLE_COLUMNS.index("CPA (m)")
    page, log = open_page(browser, out / "index.html", f"?q=head-on&sort={sort}")
    assert len(_column(page, "situation")) == _shown_count(page) == head_on
    assert set(_column(page, "situation")) == {"head-on"}
    cpas = [float(v) for v in _column(page, "CPA (m)", shown_only=False)]
    assert len(cpas) == len(result.encounters) and cpas == sorted(cpas)
    assert log["errors"] == []
    page.context.close()


def test_the_table_filters_and_sorts_as_a_person_types_and_clicks(browser, sandiego_report):
    result, out = sandiego_report
    page, log = open_page(browser, out / "index.html")
    crossing = sum(situation_or_interaction(o.summary) == "crossing" for o in result.encounters)
    assert 0 < crossing < len(result.encounters)
    page.locator("#encounters-text").fill("crossing")
    assert _shown_count(page) == len(_column(page, "situation")) == crossing
    header = page.locator("#encounters th", has_text="min sep (m)")
    header.click()
    separations = [float(v) for v in _column(page, "min sep (m)")]
    assert separations == sorted(separations)
    header.click()  # a second click sorts the other way
    assert [float(v) for v in _column(page, "min sep (m)")] == sorted(separations, reverse=True)
    page.locator("#encounters-text").fill("")
    assert _shown_count(page) == len(result.encounters)
    assert log["errors"] == []
    page.context.close()


def test_a_pair_on_the_map_leads_to_its_rows_in_the_table(browser, sandiego_report) -> None:
    result, out = sandiego_report
    numbers = pair_numbers(result)
    text = (out / "index.html").read_text(encoding="utf-8")
    # Each number on the map links to its pair...
    for number in numbers.values():
        assert f'<a xlink:href="#pair-{number}">' in text
    # ...and the link shows that pair's rows (both seats), the table numbering them the same.
    pair_id, number = sorted(numbers.items())[len(numbers) // 2]
    page, log = open_page(browser, out / "index.html", f"#pair-{number}")
    seats = [o.summary.encounter_id for o in result.encounters if o.summary.pair_id == pair_id]
    assert len(seats) >= 1
    assert sorted(_column(page, "encounter")) == sorted(seats)
    assert set(_column(page, "pair")) == {str(number)}
    assert _shown_count(page) == len(seats)
    every_pair = _column(page, "pair", shown_only=False)
    assert sorted(set(every_pair), key=int) == [str(n) for n in range(1, len(numbers) + 1)]
    assert log["errors"] == []
    page.context.close()


def test_the_pages_fetch_nothing_from_the_network(sandiego_report, stats_report) -> None:
    # The SVG's namespace names are not fetched, hence src/href/url only.
    for path in (sandiego_report[1] / "index.html", stats_report[1] / "index.html"):
        assert not re.search(r'(src|href|url)\s*[=(]\s*["\']?https?:', path.read_text())


def test_facts_give_positions_and_distances_to_audit_precision(sandiego_report) -> None:
    result, out = sandiego_report
    page = (out / "index.html").read_text(encoding="utf-8")
    summary = result.encounters[0].summary
    lat = summary.own_lat_deg_at_trigger
    assert f"<dt>own_lat_deg_at_trigger</dt><dd>{lat:.6f}</dd>" in page
    cpa = summary.cpa_m
    assert f"<dt>cpa_m</dt><dd>{cpa:.1f}</dd>" in page  # tenths: 149.8 is not the 150 threshold


@pytest.mark.parametrize("required", [False, True])
def test_without_chromium_a_browser_test_skips_with_the_reason(required: bool) -> None:
    """This file's stats page test, run with no Chromium to find: it skips and says what to
    install, or, where the browser is required (CI), it fails. The browser is asked for
    before the report is made, so that the skip is quick."""
    env = {**os.environ, CHROMIUM: "no-such-chromium"}
    env.pop(REQUIRE_BROWSER, None)
    if required:
        env[REQUIRE_BROWSER] = "1"
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-p",
            "no:cacheprovider",
            "-rs",
            "-q",
            f"{__file__}::test_the_stats_page_shows_its_table_and_histogram",
        ],
        capture_output=True,
        text=True,
        env=env,
        cwd=Path(__file__).parents[1],
        timeout=300,
    )
    assert "the browser tests need Chromium" in run.stdout, run.stdout
    if required:
        assert run.returncode == 1 and "1 error" in run.stdout, run.stdout
    else:
        assert run.returncode == 0 and "1 skipped" in run.stdout, run.stdout
        assert "apt-get install chromium" in run.stdout


# The encounter table's geometry: each header's box, and whether it is shown at all.
_HEADERS = """() => Array.from(document.querySelectorAll("#encounters th")).map(h => {
  const box = h.getBoundingClientRect();
  return {text: h.textContent, left: box.left, right: box.right, width: box.width,
          shown: h.checkVisibility()};
})"""


def test_the_table_fits_the_window_with_its_key_columns(browser, sandiego_report) -> None:
    """At 1400 × 1000 the key columns are all in the window and the table no wider than it;
    ticking "more columns" shows the others, and their cells."""
    _, out = sandiego_report
    page, log = open_page(browser, out / "index.html")
    width = VIEWPORT["width"]
    table = page.locator("#encounters").bounding_box()
    assert table is not None and table["x"] >= 0 and table["x"] + table["width"] <= width
    assert page.evaluate("document.documentElement.scrollWidth") <= width
    headers = page.evaluate(_HEADERS)
    assert [h["text"] for h in headers] == list(ENCOUNTER_TABLE_COLUMNS)
    key = [h for h in headers if h["text"] in KEY_COLUMNS]
    assert [h["text"] for h in key] == list(KEY_COLUMNS)
    assert all(h["shown"] and h["left"] >= 0 and h["right"] <= width for h in key), key
    assert not any(h["shown"] for h in headers if h["text"] in MORE_COLUMNS)
    # The key columns include what the issue found off-screen: least separation and acted.
    assert {"min sep (m)", "give-way acted", "give-way", "deciding rule"} <= set(KEY_COLUMNS)
    cpa = ENCOUNTER_TABLE_COLUMNS.index("CPA (m)")
    first_cpa = page.locator("#encounters tbody tr").first.locator("td").nth(cpa)
    assert not first_cpa.is_visible()
    page.locator("#encounters-more").check()
    headers = page.evaluate(_HEADERS)
    assert all(h["shown"] and h["width"] > 0 for h in headers), headers
    assert first_cpa.is_visible()
    page.locator("#encounters-more").uncheck()
    assert not first_cpa.is_visible()
    assert log["errors"] == []
    page.context.close()


def test_the_give_way_column_names_the_final_give_way_vessels(sandiego_report) -> None:
    result, _ = sandiego_report
    numbers = pair_numbers(result)
    for outcome in result.encounters:
        s = outcome.summary
        cells = _encounter_row(outcome, numbers)
        row = dict(zip(ENCOUNTER_TABLE_COLUMNS, cells, strict=True))
        cell = row["give-way"]
        if s.own_role_final is None:
            assert cell == ""
            continue
        for mmsi, role in ((s.own_mmsi, s.own_role_final), (s.target_mmsi, s.target_role_final)):
            assert (f"({mmsi})" in cell or cell.split(", ").count(str(mmsi)) == 1) == (
                role is Role.GIVE_WAY
            ), (cell, s.own_role_final, s.target_role_final)
        if Role.GIVE_WAY not in (s.own_role_final, s.target_role_final):
            assert cell == "none"


def test_the_title_names_the_input_time_span_query_and_chart(browser, sandiego_report) -> None:
    result, out = sandiego_report
    triggers = [o.summary.trigger_utc for o in result.encounters]
    first, last = min(triggers), max(triggers)
    span = f"{first:%Y-%m-%d %H:%M:%S} – {last:%H:%M:%S} UTC"
    page, log = open_page(browser, out / "index.html")
    title = page.title()
    assert title == page.locator("h1").inner_text()
    assert title == (
        f"Replay of {SANDIEGO_AIS.name}, {span}, query {result.query_name}, "
        f"chart {SANDIEGO_ENC.name}"
    )
    line = page.locator("p.inputs").inner_text()
    assert line.startswith(f"Input: {SANDIEGO_AIS.name}. Time span: {span} (first to last")
    assert f"Query: {result.query_name} (" in line and f"Chart: {SANDIEGO_ENC.name}." in line
    # File names only: the directories the run read from are run.json's.
    assert str(SANDIEGO_AIS.parent) not in page.content()
    assert log["errors"] == []
    page.context.close()


def test_the_time_span_is_the_query_window_when_it_has_one(sandiego_report) -> None:
    result, _ = sandiego_report
    query = {**result.manifest["query"], "time": {"start": "2022-01-03T00:00:00Z", "end": None}}
    half_open = dataclasses.replace(result, manifest={**result.manifest, "query": query})
    assert time_span(half_open) == time_span(result)
    triggers = time_span(result)
    assert triggers is not None and triggers[1] == "first to last trigger"
    query["time"] = {"start": "2022-01-03T00:00:00Z", "end": "2022-01-04T00:25:00Z"}
    assert time_span(half_open) == (
        "2022-01-03 00:00:00 – 2022-01-04 00:25:00 UTC",
        "query window",
    )
    bare = dataclasses.replace(result, pairs=(), manifest={})
    assert time_span(bare) is None
    assert page_title(bare) == f"Replay, query {result.query_name}"
