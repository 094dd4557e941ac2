"""The HTML reports, loaded in a real browser (Debian's headless Chromium, ``--dump-dom``):
the rendered page must hold the table rows, the map and every figure."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from colregs9_cli.core.rows import situation_or_interaction
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.stats import run_stats
from colregs9_cli.report.html_report import ENCOUNTER_TABLE_COLUMNS, pair_numbers

from fixture_files import DMA26, NMEA

CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--virtual-time-budget=5000",
    "--dump-dom",
)


def rendered(page: Path, tmp_path: Path, query: str = "") -> str:
    """The page's DOM after its scripts ran, as Chromium rendered it (no network)."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    assert browser, "Chromium is needed for the browser tests: apt-get install chromium"
    profile = tmp_path / f"chromium-profile-{len(query)}"
    result = subprocess.run(
        [browser, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", page.as_uri() + query],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return result.stdout


@pytest.fixture(scope="module")
def national_report(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("html") / "report"
    result = run_replay([NMEA], out_dir=out, plots=True)
    return result, out


def _rows(dom: str) -> list[str]:
    body = dom[dom.index('<table class="sortable" id="encounters">') :]
    body = body[body.index("<tbody>") : body.index("</tbody>")]
    return re.findall(r"<tr( class=\"hidden\")?>", body)


def _cells(dom: str, column: str, shown_only: bool = True) -> list[str]:
    """The text of one column's cells, in the rendered order (the shown rows only)."""
    body = dom[dom.index('<table class="sortable" id="encounters">') :]
    body = body[body.index("<tbody>") : body.index("</tbody>")]
    index = ENCOUNTER_TABLE_COLUMNS.index(column)
    cells = []
    for hidden, row in re.findall(r"<tr( class=\"hidden\")?>(.*?)</tr>", body):
        if hidden and shown_only:
            continue
        texts = [re.sub(r"<[^>]+>", "", cell) for cell in re.findall(r"<td[^>]*>(.*?)</td>", row)]
        cells.append(texts[index])
    return cells


def test_replay_page_shows_every_encounter_and_figure(national_report, tmp_path) -> None:
    result, out = national_report
    page = out / "index.html"
    # Nothing is fetched from the network (the SVG's namespace names are not fetched).
    assert not re.search(r'(src|href|url)\s*[=(]\s*["\']?https?:', page.read_text())
    dom = rendered(page, tmp_path)
    assert len(_rows(dom)) == len(result.encounters) == 24
    # Every figure loaded: the page replaces one that does not with a "missing" note.
    assert dom.count('class="figure"') == 24
    assert 'class="missing"' not in dom
    assert dom.count('<section class="encounter"') == 24
    assert "<svg" in dom  # the overview map, drawn inline
    for outcome in result.encounters:
        assert f'href="#enc-{outcome.summary.encounter_id}"' in dom


def test_replay_page_filters_and_sorts_in_the_browser(national_report, tmp_path) -> None:
    result, out = national_report
    head_on = sum(situation_or_interaction(o.summary) == "head-on" for o in result.encounters)
    assert 0 < head_on < len(result.encounters)
    sort = ENCOUNTER_TABLE_COLUMNS.index("CPA (m)")
    dom = rendered(out / "index.html", tmp_path, f"?q=head-on&sort={sort}")
    rows = _rows(dom)
    assert sum(hidden == "" for hidden in rows) == head_on
    assert f'<span id="encounters-shown">{head_on}</span>' in dom
    cpas = [float(v) for v in _cells(dom, "CPA (m)", shown_only=False)]
    assert len(cpas) == len(result.encounters) and cpas == sorted(cpas)


def test_a_pair_on_the_map_leads_to_its_rows_in_the_table(national_report, tmp_path) -> None:
    result, out = national_report
    numbers = pair_numbers(result)
    page = (out / "index.html").read_text(encoding="utf-8")
    # Each number on the map links to its pair...
    for number in numbers.values():
        assert f'<a xlink:href="#pair-{number}">' in page
    # ...and the link shows that pair's rows (both seats), the table numbering them the same.
    pair_id, number = sorted(numbers.items())[len(numbers) // 2]
    dom = rendered(out / "index.html", tmp_path, f"#pair-{number}")
    seats = [o.summary.encounter_id for o in result.encounters if o.summary.pair_id == pair_id]
    assert len(seats) >= 1
    assert sorted(_cells(dom, "encounter")) == sorted(seats)
    assert set(_cells(dom, "pair")) == {str(number)}
    assert f'<span id="encounters-shown">{len(seats)}</span>' in dom
    every_pair = _cells(dom, "pair", shown_only=False)
    assert sorted(set(every_pair), key=int) == [str(n) for n in range(1, len(numbers) + 1)]


def test_a_missing_figure_is_marked_not_broken(national_report, tmp_path) -> None:
    _, out = national_report
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    first = sorted((copy / "encounters").glob("*.png"))[0]
    first.unlink()
    dom = rendered(copy / "index.html", tmp_path)
    assert dom.count('class="missing"') == 1
    assert f"figure not found: encounters/{first.name}" in dom


def test_stats_page_shows_its_table_and_histograms(tmp_path) -> None:
    run = run_stats([DMA26], out_dir=tmp_path / "stats")
    dom = rendered(tmp_path / "stats" / "index.html", tmp_path)
    body = dom[dom.index("<tbody>") : dom.index("</tbody>")]
    assert body.count("<tr") == len(run.result.to_frame()) == 3
    assert dom.count('class="figure"') == 1
    assert 'class="missing"' not in dom


def test_facts_give_positions_and_distances_to_audit_precision(national_report) -> None:
    result, out = national_report
    page = (out / "index.html").read_text(encoding="utf-8")
    summary = result.encounters[0].summary
    lat = summary.own_lat_deg_at_trigger
    assert f"<dt>own_lat_deg_at_trigger</dt><dd>{lat:.6f}</dd>" in page
    cpa = summary.cpa_m
    assert f"<dt>cpa_m</dt><dd>{cpa:.1f}</dd>" in page  # tenths: 149.8 is not the 150 threshold
