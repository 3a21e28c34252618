"""Fig. 5: the amplitude of the secondary solitary wave (SSW) against F_m (log-log)."""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import usable_rows
from chain.report import picks
from chain.report.style import (
    STYLE,
    add_legend,
    axes_or_new,
    chain_marker,
    model_colors,
    plain_numbers,
    source_label,
)


def fig5_ssw_vs_force(
    ssw: pd.DataFrame,
    fits: pd.DataFrame | None = None,
    *,
    experiment_label: str = "experiment",
    ax=None,
) -> Figure:
    """Fig. 5: amplitude of the secondary solitary wave (SSW) against the incident
    amplitude F_m (log-log): simulation filled markers, experiment open markers, one
    marker per chain (circle N = 25, cross/square N = 26), a colour per model, and the
    proportional fits SSW = slope x F_m (thin lines, slope in the legend).

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv``.
    fits : DataFrame, optional
        ``ssw_fits.csv``.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 6.4, 5.0)
    rows = usable_rows(picks.main_method(ssw), ["F_m_N", "ssw_N"], "Fig. 5 SSW rows", positive=True)
    colors = model_colors(picks.simulated_models(rows))
    all_n = sorted({int(n) for n in rows["N"]})
    slopes = picks.chain_slopes(fits)
    with mpl.rc_context(STYLE):
        for (source, model, n), group in rows.groupby(["source", "model", "N"], sort=False):
            n = int(n)
            marker = chain_marker(n, all_n)
            if marker == "x" and source == "simulation":
                marker = "s"  # a cross cannot be filled
            color = colors.get(model, "black") if source == "simulation" else "black"
            filled = source == "simulation"
            name = source_label(source, experiment_label)
            label = f"{name}, {model}, N = {n}" if filled else f"{name}, N = {n}"
            slope = slopes.get((source, model, n))
            if slope is not None and np.isfinite(slope[0]):
                label += f" (slope {slope[0]:.2e} ± {slope[1]:.1e})"
                grid = np.geomspace(group["F_m_N"].min(), group["F_m_N"].max(), 20)
                ax.plot(grid, slope[0] * grid, color=color, lw=0.7, ls="-", alpha=0.7)
            ax.plot(
                group["F_m_N"],
                group["ssw_N"],
                ls="none",
                marker=marker,
                ms=4.5,
                color=color,
                mfc=color if filled else "none",
                mec=color,
                mew=0.9,
                label=label,
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        plain_numbers(ax.xaxis)
        plain_numbers(ax.yaxis)
        ax.set_xlabel("incident amplitude F$_m$ (N)")
        ax.set_ylabel("SSW amplitude (N)")
        ax.set_title(
            "Secondary solitary waves: simulation filled, experiment open markers", loc="left"
        )
        add_legend(fig, ax, own, "upper left")
    return fig
