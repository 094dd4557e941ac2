"""`colregs9 swing`: the paper's rate-of-swing table, CSV and figure."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.backends.backend_agg import FigureCanvasAgg
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.core.manoeuvrability import reference_vessels
from colregs9_cli.jobs.swing import run_swing
from colregs9_cli.outputs import is_report
from colregs9_cli.report.swing_plot import rate_of_swing_figure


def test_run_swing_writes_the_table(tmp_path: Path) -> None:
    report = run_swing(tmp_path / "swing")
    assert report.out_dir == tmp_path / "swing"
    assert report.csv_path == tmp_path / "swing" / "rate_of_swing.csv"
    # run.json marks the directory as a colregs9 report, which a rerun replaces
    assert is_report(report.out_dir)
    written = pd.read_csv(report.csv_path)
    assert len(written) == 14
    np.testing.assert_allclose(
        written["rate_of_swing_deg_per_m"], 360.0 / (2.0 * math.pi * written["turn_radius_m"])
    )
    assert written.loc[0, "vessel_type"] == "fishing"
    assert written.loc[0, "rate_of_swing_deg_per_m"] == np.float64(360.0 / (2 * math.pi * 74.1))
    assert report.png_path.stat().st_size > 10_000
    # fishing, r = 74.1 m: 360 / (2π·74.1) = 0.77322… deg/m
    assert "0.7732" in report.text


def test_figure_plots_each_class_at_its_lengths_and_rates() -> None:
    table = reference_vessels()
    figure = rate_of_swing_figure(table, fixed_deg_per_m=0.2)
    ax = figure.axes[0]
    scatters = {c.get_label(): c.get_offsets() for c in ax.collections}
    assert set(scatters) == set(table["vessel_type"])
    for vessel_type, rows in table.groupby("vessel_type"):
        expected = rows[["length_m", "rate_of_swing_deg_per_m"]].to_numpy()
        np.testing.assert_allclose(np.asarray(scatters[vessel_type]), expected)
    markers = {c.get_label(): c.get_paths()[0].vertices.shape[0] for c in ax.collections}
    assert markers["tanker"] != markers["coastguard"]  # square vs triangle, as in the paper
    colours = [tuple(c.get_facecolor()[0]) for c in ax.collections]
    assert len(set(colours)) == len(colours)  # no two classes share a colour
    levels = sorted(line.get_ydata()[0] for line in ax.get_lines())
    assert levels == [table["rate_of_swing_deg_per_m"].min(), 0.2]
    FigureCanvasAgg(figure).draw()


def test_swing_command(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["swing", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "rate_of_swing.csv").is_file()
    assert (tmp_path / "rate_of_swing.png").is_file()
    assert "rate_of_swing_deg_per_m" in result.output
    assert result.output.count("bulk carrier") == 3
    assert "0.0773" in result.output
