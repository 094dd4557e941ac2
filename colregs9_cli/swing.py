"""``colregs9 swing``: the paper's rate-of-swing table and figure for the 14 reference vessels."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd

from .manoeuvrability import ManoeuvrabilityParams, reference_vessels
from .report.atomic import save_figure, write_csv
from .report.swing_plot import rate_of_swing_figure

DEFAULT_OUT_DIR = Path("reports/swing")
CSV_NAME = "rate_of_swing.csv"
PNG_NAME = "rate_of_swing.png"


@dataclass(frozen=True)
class SwingReport:
    table: pd.DataFrame
    csv_path: Path
    png_path: Path
    text: str


def format_swing_table(table: pd.DataFrame) -> str:
    """The table as fixed-width text, the rate of swing to four decimals."""
    shown = table.copy()
    shown["rate_of_swing_deg_per_m"] = shown["rate_of_swing_deg_per_m"].map("{:.4f}".format)
    return shown.to_string(index=False) + "\n"


def run_swing(out_dir: Path | None = None) -> SwingReport:
    """Write rate_of_swing.csv and rate_of_swing.png to ``out_dir`` (default reports/swing/)."""
    out_dir = DEFAULT_OUT_DIR if out_dir is None else Path(out_dir)
    table = reference_vessels()
    csv_path = out_dir / CSV_NAME
    png_path = out_dir / PNG_NAME
    write_csv(csv_path, table)
    defaults = ManoeuvrabilityParams()
    figure = rate_of_swing_figure(table, defaults.swing_deg_per_m)
    try:
        save_figure(png_path, figure, dpi=150)
    finally:
        plt.close(figure)
    return SwingReport(table, csv_path, png_path, format_swing_table(table))
