"""What-if figure: the SSW slope against the number of beads N, even against odd chains."""

from __future__ import annotations

import matplotlib as mpl
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import usable_rows
from chain.report.figures import picks
from chain.report.figures.style import STYLE, add_legend, axes_or_new, draw_even_odd, model_colors
from chain.report.naming import series_name


def fig_parity_ssw_vs_N(
    ssw_fits: pd.DataFrame, *, experiment_label: str = "experiment", ax=None
) -> Figure:
    """SSW slope (SSW amplitude / F_m) against the number of beads N, even chains
    (waves meet at a contact) filled, odd chains (waves meet at a bead) open; a colour
    per model, error bars one standard error.

    Parameters
    ----------
    ssw_fits : DataFrame
        ``ssw_fits.csv``.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 6.0, 4.4)
    ssw_fits = picks.main_method(ssw_fits)
    rows = ssw_fits[~picks.is_pooled(ssw_fits["N"])].assign(ok=True)
    rows = usable_rows(rows, ["slope", "slope_stderr"], "parity figure: SSW fits").copy()
    rows["N"] = rows["N"].astype(int)
    colors = model_colors(picks.simulated_models(rows))
    with mpl.rc_context(STYLE):
        for (source, model), group in rows.groupby(["source", "model"], sort=False):
            group = group.sort_values("N")
            color = colors.get(model, "black") if source == "simulation" else "black"
            name = series_name(source, model, experiment_label)
            draw_even_odd(ax, group["N"], group["slope"], group["slope_stderr"], color, name)
        ax.set_xlabel("number of beads N")
        ax.set_ylabel("SSW amplitude / incident amplitude")
        ax.set_title(
            "Parity: even chains (waves meet at a contact) against odd (at a bead)", loc="left"
        )
        ax.xaxis.set_major_locator(mpl.ticker.MaxNLocator(integer=True))
        if rows.empty:
            ax.text(
                0.5,
                0.5,
                "SSW not resolved at the sensors of any chain: no slope to plot",
                transform=ax.transAxes,
                ha="center",
                va="center",
                color="0.35",
            )
        else:
            add_legend(fig, ax, own, "best")
    return fig
