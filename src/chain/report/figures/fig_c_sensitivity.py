"""Supplementary figure: C of Delta = C F_m^(-1/6) against our choices (estimator, eta,
sensor pair, amplitude range), with error bars (tables/c_sensitivity.csv)."""

from __future__ import annotations

import matplotlib as mpl
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import is_ok
from chain.report.figures.style import STYLE, add_legend, axes_or_new, chain_marker

#: Group titles of the choices.
_CHOICE_NAMES = {
    "estimator": "pulse estimator",
    "eta_us": "η (µs)",
    "sensors": "sensors (beads towards the collision)",
    "amplitudes": "amplitudes",
}


def fig_c_sensitivity(table: pd.DataFrame, *, ax=None) -> Figure:
    """C (µs N^1/6) with its standard error for every row of ``c_sensitivity.csv``: one
    category per (choice, value) on the x axis, grouped by choice; a marker per chain
    (circle N = 25, cross N = 26, filled square pooled); the headline C as a dotted line.

    Parameters
    ----------
    table : DataFrame
        ``c_sensitivity.csv`` (:func:`chain.studies.c_sensitivity.c_sensitivity_table`).
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 7.2, 4.4)
    cases = list(dict.fromkeys(zip(table["choice"], table["value"])))
    position = {case: i for i, case in enumerate(cases)}
    with mpl.rc_context(STYLE):
        _draw_points(ax, table, position)
        headline = table[is_ok(table, "headline") & (table["N"].astype(str) == "pooled")]
        if not headline.empty:
            c = float(headline["C"].iloc[0])
            ax.axhline(c, color="0.6", lw=0.8, ls=":", label=f"headline choice, pooled: {c:.2f}")
        ax.set_xticks(range(len(cases)))
        ax.set_xticklabels([f"{value}" for _, value in cases], rotation=55, ha="right", fontsize=7)
        _draw_groups(ax, table, cases, position)
        _draw_notes(ax, table, position)
        ax.set_xlim(-0.5, len(cases) - 0.5)
        ax.set_ylabel("C (µs N$^{1/6}$), |Δ| = C F$_m^{-1/6}$")
        ax.set_title(
            "C against our choices (simulation; one choice changed at a time)", loc="left", pad=14
        )
        add_legend(fig, ax, own, "lower left")
    return fig


def _draw_points(ax, table: pd.DataFrame, position: dict) -> None:
    """C with error bars, one marker per chain, side by side within a category."""
    chains = sorted({str(n) for n in table["N"]}, key=lambda n: (n == "pooled", n))
    beads = [int(n) for n in chains if n != "pooled"]
    for k, n in enumerate(chains):
        rows = table[table["N"].astype(str) == n]
        x = [
            position[c] + 0.18 * (k - (len(chains) - 1) / 2)
            for c in zip(rows["choice"], rows["value"])
        ]
        marker = "s" if n == "pooled" else chain_marker(int(n), beads)
        ax.errorbar(
            x,
            rows["C"],
            yerr=rows["C_stderr"],
            ls="none",
            marker=marker,
            ms=4.5,
            mfc="black" if n == "pooled" else "none",
            color="black" if n == "pooled" else "0.45",
            capsize=2,
            label="N pooled" if n == "pooled" else f"N = {n}",
        )


def _draw_groups(ax, table: pd.DataFrame, cases: list, position: dict) -> None:
    """Alternating bands and a title over the categories of each choice."""
    for choice in dict.fromkeys(table["choice"]):
        members = [position[c] for c in cases if c[0] == choice]
        ax.axvspan(
            min(members) - 0.5,
            max(members) + 0.5,
            color="0.94" if len(members) and members[0] % 2 else "white",
            zorder=0,
        )
        ax.text(
            (min(members) + max(members)) / 2,
            1.01,
            _CHOICE_NAMES.get(choice, choice),
            transform=ax.get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=7,
        )


def _draw_notes(ax, table: pd.DataFrame, position: dict) -> None:
    """The table's note (a chain without a usable delay) above its pooled marker."""
    missing = table[(table["N"].astype(str) == "pooled") & (table["note"].fillna("") != "")]
    for row in missing.itertuples(index=False):
        ax.annotate(
            row.note.split(";")[0],
            (position[(row.choice, row.value)], row.C),
            xytext=(0, 9),
            textcoords="offset points",
            ha="center",
            fontsize=5.5,
            color="0.3",
        )
