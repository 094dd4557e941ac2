"""The paper's figure "Shallow water rate of swing for the 14 different vessels"."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

# The paper's pgfplots classes: squares for the first four, triangles for the rest. Each class
# has a colour of its own (the paper repeats four), so that no two classes look alike.
CLASS_STYLES: dict[str, tuple[str, str]] = {
    "tanker": ("s", "tab:blue"),
    "fishing": ("s", "tab:red"),
    "bulk carrier": ("s", "tab:orange"),
    "supply": ("s", "black"),
    "coastguard": ("^", "tab:cyan"),
    "container": ("^", "tab:pink"),
    "cruiseship": ("^", "tab:olive"),
    "vehicle carrier": ("^", "tab:brown"),
}
OTHER_STYLE = ("D", "0.5")


def rate_of_swing_figure(
    table: pd.DataFrame, fixed_deg_per_m: float | None = 0.2, alpha: float | None = None
) -> Figure:
    """Rate of swing against length, one marker per vessel class (scatter label = class).

    Horizontal lines: the table's lower bound and the paper's fixed δ_swing; with ``alpha``,
    also the fixed value scaled by α.
    """
    figure = Figure(figsize=(7, 5), layout="constrained")
    ax = figure.subplots()
    for vessel_type, rows in table.groupby("vessel_type", sort=False):
        marker, colour = CLASS_STYLES.get(str(vessel_type), OTHER_STYLE)
        ax.scatter(
            rows["length_m"],
            rows["rate_of_swing_deg_per_m"],
            marker=marker,
            color=colour,
            s=45,
            label=str(vessel_type),
            zorder=3,
        )
    lower = float(table["rate_of_swing_deg_per_m"].min())
    ax.axhline(lower, color="0.3", linestyle="--", linewidth=0.8, label=f"lower bound {lower:.3f}")
    if fixed_deg_per_m is not None:
        ax.axhline(
            fixed_deg_per_m,
            color="tab:green",
            linestyle=":",
            linewidth=1.0,
            label=f"paper's fixed δ_swing {fixed_deg_per_m:g}",
        )
        if alpha is not None:
            ax.axhline(
                alpha * fixed_deg_per_m,
                color="tab:purple",
                linestyle="-.",
                linewidth=0.8,
                label=f"α·δ_swing = {alpha:g}·{fixed_deg_per_m:g}",
            )
    ax.set_xlabel("Vessel length (m)")
    ax.set_ylabel("Rate of swing (deg/m)")
    ax.set_title("Shallow water rate of swing for the 14 different vessels")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="upper right")
    return figure
