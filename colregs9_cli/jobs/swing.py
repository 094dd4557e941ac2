"""``colregs9 swing``: the paper's rate-of-swing table and figure for the 14 reference vessels."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..core.manoeuvrability import ManoeuvrabilityParams, reference_vessels
from ..outputs import (
    REPORT_MARKER,
    check_out_dir,
    report_directory,
    save_figure,
    write_csv,
    write_json,
)
from ..provenance import run_header
from ..report.swing_plot import rate_of_swing_figure

DEFAULT_OUT_DIR = Path("reports/swing")
CSV_NAME = "rate_of_swing.csv"
PNG_NAME = "rate_of_swing.png"


@dataclass(frozen=True)
class SwingReport:
    table: pd.DataFrame
    out_dir: Path
    csv_path: Path
    png_path: Path
    text: str


def format_swing_table(table: pd.DataFrame) -> str:
    """The table as fixed-width text, the rate of swing to four decimals."""
    shown = table.copy()
    shown["rate_of_swing_deg_per_m"] = shown["rate_of_swing_deg_per_m"].map("{:.4f}".format)
    return shown.to_string(index=False) + "\n"


def run_swing(out_dir: Path | None = None, overwrite: bool = False) -> SwingReport:
    """Write rate_of_swing.csv, rate_of_swing.png and run.json to ``out_dir`` (default
    reports/swing/), which is replaced as ``stats`` and ``replay`` replace theirs.

    Errors: an ``out_dir`` that cannot take a report, or, unless ``overwrite``, holds a report
    of another command or files colregs9 did not write (``OutputError``, exit 2), before any
    work (``outputs.check_out_dir``).
    """
    out_dir = DEFAULT_OUT_DIR if out_dir is None else Path(out_dir)
    check_out_dir(out_dir, overwrite, command="swing")
    table = reference_vessels()
    defaults = ManoeuvrabilityParams()
    # run.json marks the directory as a colregs9 report, which a rerun may then replace.
    manifest = {**run_header("swing"), "fixed_swing_deg_per_m": defaults.swing_deg_per_m}
    figure = rate_of_swing_figure(table, defaults.swing_deg_per_m)
    with report_directory(out_dir, overwrite) as staging:
        write_csv(staging / CSV_NAME, table)
        save_figure(staging / PNG_NAME, figure, dpi=150)
        write_json(staging / REPORT_MARKER, manifest)
    return SwingReport(
        table, out_dir, out_dir / CSV_NAME, out_dir / PNG_NAME, format_swing_table(table)
    )
