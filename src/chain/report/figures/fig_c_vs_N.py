"""Sweep figure: the crossing-delay constant C against the number of beads N.

Drawn from ``tables/sweep.csv`` (:func:`chain.studies.sweep.sweep_table`), one
colour per contact model (eta), even chains (the waves meet at a contact) filled, odd
chains (at a bead) open, error bars one standard error; the paper's measured C
(N = 25, 26) as a grey band for scale. Its companion, the SSW slope against N, is
:func:`chain.report.figures.fig_parity_ssw_vs_N.fig_parity_ssw_vs_N`.
"""

from __future__ import annotations

import matplotlib as mpl
import pandas as pd
from matplotlib.figure import Figure

from chain.report.figures.style import STYLE, draw_even_odd, model_colors
from chain.report.numbers.paper import PAPER


def fig_c_vs_N(sweep: pd.DataFrame, *, ax=None) -> Figure:
    """C of |Delta| = C F_m^(-1/6) against N, a colour per model, even filled, odd open.

    Parameters
    ----------
    sweep : DataFrame
        ``tables/sweep.csv``: model, eta_s (s), N, C_us_N16, C_stderr_us_N16 (us N^1/6).
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    with mpl.rc_context(STYLE):
        if own:
            fig = Figure(figsize=(6.0, 4.4), layout="constrained")
            ax = fig.add_subplot()
        fig = ax.figure
        colors = model_colors(list(dict.fromkeys(sweep["model"])))
        c_exp, c_err = PAPER["C_exp_us_N16"], PAPER["C_exp_err_us_N16"]
        ax.axhspan(c_exp - c_err, c_exp + c_err, color="0.85", lw=0)
        ax.axhline(c_exp, color="0.5", lw=0.8, label="paper, measured C (N = 25, 26)")
        for model, group in sweep.groupby("model", sort=False):
            group = group.sort_values("N")
            color = colors[model]
            eta_us = group["eta_s"].iloc[0] * 1e6
            draw_even_odd(
                ax,
                group["N"],
                group["C_us_N16"],
                group["C_stderr_us_N16"],
                color,
                f"{model} (η = {eta_us:.2g} µs)",
            )
        ax.set_xlabel("number of beads N")
        ax.set_ylabel("C (µs N$^{1/6}$), fit of |Δ| = C F$_m^{-1/6}$")
        ax.set_title("Crossing delay constant C against N (simulation)", loc="left")
        ax.xaxis.set_major_locator(mpl.ticker.MaxNLocator(integer=True))
        if own:
            handles, labels = ax.get_legend_handles_labels()
            fig.legend(
                handles, labels, loc="outside lower center", ncol=2, fontsize=6, frameon=False
            )
        else:
            ax.legend(loc="best", fontsize=6, frameon=False)
    return fig
