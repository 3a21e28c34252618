"""The mechanism study's figure: SSW/F_m at S2 per mechanism and setting against the
frictionless value, N = 25 and N = 26 (tables/ssw_mechanisms.csv)."""

from __future__ import annotations

import math

import matplotlib as mpl
import pandas as pd
from matplotlib.figure import Figure

from chain.report.style import STYLE, add_legend, axes_or_new, chain_marker

#: Percent per unit ratio.
PERCENT = 100.0

#: A ratio to the frictionless value that counts as "significantly larger" (issue 24).
SIGNIFICANT_RATIO = 2.0


def fig_ssw_mechanisms(table: pd.DataFrame, reference: str, *, ax=None) -> Figure:
    """SSW/F_m (%) with its standard error, one category per (mechanism, setting) on
    the x axis, a marker per chain (circle N = 25, cross N = 26); per chain the value
    of the ``reference`` setting as a dashed line and twice it as a dotted line (the
    "significantly larger" mark). A point without a value is written as "n/r" (no SSW
    measured at S2).

    Parameters
    ----------
    table : DataFrame
        ``ssw_mechanisms.csv`` (:func:`chain.pipeline.mechanisms.mechanism_rows`).
    reference : str
        The ``setting`` of the frictionless reference.
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 7.2, 4.2)
    cases = list(dict.fromkeys(zip(table["mechanism"], table["setting"])))
    position = {case: i for i, case in enumerate(cases)}
    chains = sorted(int(n) for n in table["N"].unique())
    with mpl.rc_context(STYLE):
        for k, n_beads in enumerate(chains):
            rows = table[table["N"] == n_beads]
            shift = 0.15 * (k - (len(chains) - 1) / 2)
            _draw_chain(ax, rows, position, shift, n_beads, chain_marker(n_beads, chains))
            base = rows[rows["setting"] == reference]["ssw_over_Fm"]
            if len(base) and math.isfinite(float(base.iloc[0])):
                value = PERCENT * float(base.iloc[0])
                style = {"color": "0.35" if k else "0.6", "lw": 0.8}
                ax.axhline(value, ls="--", label=f"N = {n_beads} frictionless", **style)
                ax.axhline(SIGNIFICANT_RATIO * value, ls=":", label=f"N = {n_beads}: 2 x", **style)
        ax.set_xticks(range(len(cases)))
        ax.set_xticklabels([s for _, s in cases], rotation=40, ha="right", fontsize=7)
        ax.set_xlim(-0.5, len(cases) - 0.5)
        ax.set_ylim(bottom=0)
        ax.set_ylabel("SSW / F$_m$ at S2 (%)")
        ax.set_title("Secondary-wave size per mechanism (models, not data)", loc="left", fontsize=9)
        add_legend(fig, ax, own, "upper left")
    return fig


def _draw_chain(ax, rows: pd.DataFrame, position: dict, shift: float, n_beads, marker) -> None:
    """One chain's points with error bars; "n/r" where the table has no value."""
    x = [position[c] + shift for c in zip(rows["mechanism"], rows["setting"])]
    ax.errorbar(
        x,
        PERCENT * rows["ssw_over_Fm"],
        yerr=PERCENT * rows["ssw_over_Fm_err"],
        ls="none",
        marker=marker,
        ms=5,
        mfc="none",
        color="black",
        capsize=2,
        label=f"N = {n_beads}",
    )
    for xi, value in zip(x, rows["ssw_over_Fm"]):
        if not math.isfinite(float(value)):
            ax.text(
                xi,
                0.02,
                "n/r",
                transform=ax.get_xaxis_transform(),
                ha="center",
                fontsize=6,
                color="0.4",
            )
