"""Fig. 5: the amplitude of the secondary solitary wave (SSW) against F_m (log-log)."""

from __future__ import annotations

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import usable_rows
from chain.report import picks
from chain.report.printed import plus_minus
from chain.report.style import (
    STYLE,
    add_legend,
    axes_or_new,
    chain_marker,
    model_colors,
    plain_numbers,
    source_label,
)

#: Legend note of a series none of whose shots has an SSW resolved at the sensors.
NOT_RESOLVED_NOTE = "SSW not resolved at the sensors"


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
    proportional fits SSW = slope x F_m (thin lines, slope in the legend). Only SSW
    resolved at the sensor are drawn (``ok`` rows of ``ssw.csv``); a series with none
    says so in its legend entry (with its number of readings, shots x sensors) instead
    of plotting a floor.

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
    every = picks.main_method(ssw)
    rows = usable_rows(every, ["F_m_N", "ssw_N"], "Fig. 5 SSW rows", positive=True)
    colors = model_colors(picks.simulated_models(every))
    all_n = sorted({int(n) for n in every["N"]})
    slopes = picks.chain_slopes(fits)
    keys = ["source", "model", "N"]
    with mpl.rc_context(STYLE):
        for (source, model, n), shots in every.groupby(keys, sort=False):
            group = rows[(rows["source"] == source) & (rows["model"] == model) & (rows["N"] == n)]
            style, label = _series_style(source, model, int(n), colors, all_n, experiment_label)
            if group.empty:
                label += f": SSW not resolved (0 of {len(shots)})"
            slope = slopes.get((source, model, int(n)))
            if not group.empty and slope is not None and np.isfinite(slope[0]):
                label += f" (slope {plus_minus(*slope, style='mathtext')})"
                grid = np.geomspace(group["F_m_N"].min(), group["F_m_N"].max(), 20)
                ax.plot(grid, slope[0] * grid, color=style["color"], lw=0.7, ls="-", alpha=0.7)
            ax.plot(group["F_m_N"], group["ssw_N"], ls="none", ms=4.5, label=label, **style)
        ax.set_xscale("log")
        ax.set_yscale("log")
        if rows.empty:
            _empty_axes(ax, every)
        plain_numbers(ax.xaxis)
        plain_numbers(ax.yaxis)
        ax.set_xlabel("incident amplitude F$_m$ (N)")
        ax.set_ylabel("SSW amplitude (N)")
        ax.set_title(
            "Secondary solitary waves: simulation filled, experiment open markers", loc="left"
        )
        add_legend(fig, ax, own, "upper left")
    return fig


def _series_style(source, model, n, colors, all_n, experiment_label) -> tuple[dict, str]:
    """Marker style and legend label of one series."""
    marker = chain_marker(n, all_n)
    if marker == "x" and source == "simulation":
        marker = "s"  # a cross cannot be filled
    color = colors.get(model, "black") if source == "simulation" else "black"
    filled = source == "simulation"
    name = source_label(source, experiment_label)
    label = f"{name}, {model}, N = {n}" if filled else f"{name}, N = {n}"
    style = {"marker": marker, "color": color, "mec": color, "mew": 0.9}
    style["mfc"] = color if filled else "none"
    return style, label


def _empty_axes(ax, every: pd.DataFrame) -> None:
    """Axes with no resolved SSW anywhere: the F_m range of the shots and SSW from 0.1 %
    to 10 % of it, with a note in the middle."""
    forces = pd.to_numeric(every["F_m_N"], errors="coerce")
    forces = forces[np.isfinite(forces) & (forces > 0)]
    low, high = (forces.min(), forces.max()) if len(forces) else (1.0, 1000.0)
    ax.set_xlim(0.8 * low, 1.25 * high)
    ax.set_ylim(1e-3 * low, 0.1 * high)
    ax.text(
        0.5,
        0.5,
        f"{NOT_RESOLVED_NOTE} in any series",
        transform=ax.transAxes,
        ha="center",
        va="center",
        fontsize=8,
        color="0.35",
    )
