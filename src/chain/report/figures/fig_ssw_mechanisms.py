"""The mechanism study's figure: SSW/F_m at S2 per mechanism and setting against the
frictionless value, N = 25 and N = 26 (tables/ssw_mechanisms.csv)."""

from __future__ import annotations

import math
import textwrap

import matplotlib as mpl
import pandas as pd
from matplotlib.figure import Figure

from chain.report.figures.style import STYLE, add_legend, axes_or_new, chain_marker
from chain.report.numbers.mechanisms import SIGNIFICANT_RATIO

#: Percent per unit ratio.
PERCENT = 100.0

#: Colour of the first and second chain (markers and reference dashes).
CHAIN_COLORS = ("#1f77b4", "#d95f02")

#: The marks of a chain's reference at each category: (times the reference, dash, name).
REFERENCE_MARKS = ((1, "--", "reference"), (SIGNIFICANT_RATIO, ":", "2 x reference"))


def fig_ssw_mechanisms(table: pd.DataFrame, *, ax=None) -> Figure:
    """SSW/F_m (%) with its standard error, one category per (mechanism, setting) on
    the x axis, a marker and colour per chain (circle N = 25, cross N = 26); at each category, per
    chain, the value of that mechanism's reference (the frictionless LAMMPS chain, or
    the virtual experiment as configured) as a dash and twice it (the mark of
    "significantly larger") as a dotted dash. A point without a value is written "n/r".

    Parameters
    ----------
    table : DataFrame
        ``ssw_mechanisms.csv`` (:func:`chain.studies.mechanism_table.mechanism_rows`).
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 7.6, 4.6)
    cases = list(dict.fromkeys(zip(table["mechanism"], table["setting"])))
    position = {case: i for i, case in enumerate(cases)}
    chains = sorted(int(n) for n in table["N"].unique())
    with mpl.rc_context(STYLE):
        for k, n_beads in enumerate(chains):
            rows = table[table["N"] == n_beads]
            shift = 0.15 * (k - (len(chains) - 1) / 2)
            _draw_references(ax, rows, position, shift, n_beads, k)
            marker = chain_marker(n_beads, chains)
            _draw_chain(ax, rows, position, shift, n_beads, marker, CHAIN_COLORS[k % 2])
        _draw_groups(ax, cases, position)
        ax.set_xticks(range(len(cases)))
        ax.set_xticklabels([_tick(setting) for _, setting in cases], fontsize=5.5)
        ax.set_xlim(-0.5, len(cases) - 0.5)
        ax.set_ylim(bottom=0)
        ax.set_ylabel("SSW / F$_m$ at S2 (%)")
        ax.set_title("Secondary-wave size per mechanism (models, not data)", loc="left", pad=38)
        add_legend(fig, ax, own, "upper left")
    return fig


def _tick(setting: str) -> str:
    """A setting label on short lines: one per override, long ones broken after "="."""
    parts = setting.replace(", ", "; ").split("; ")
    return "\n".join(p.replace("=", "=\n") if len(p) > 14 else p for p in parts)


def _draw_references(ax, rows: pd.DataFrame, position: dict, shift, n_beads, k) -> None:
    """Per category, the reference value (SSW/F_m over the ratio) and twice it."""
    color = CHAIN_COLORS[k % 2]
    for number, row in enumerate(rows.itertuples(index=False)):
        reference = row.ssw_over_Fm / row.ratio_to_frictionless
        if not math.isfinite(reference):
            continue
        x = position[(row.mechanism, row.setting)] + shift
        for factor, dash, name in REFERENCE_MARKS:
            level = factor * PERCENT * reference
            label = f"N = {n_beads}: {name}" if number == 0 else None
            ax.hlines(level, x - 0.12, x + 0.12, colors=color, lw=1.0, ls=dash, label=label)


def _draw_groups(ax, cases: list, position: dict) -> None:
    """Alternating bands and a title over the settings of each mechanism."""
    for number, mechanism in enumerate(dict.fromkeys(m for m, _ in cases)):
        members = [position[c] for c in cases if c[0] == mechanism]
        lo, hi = min(members) - 0.5, max(members) + 0.5
        ax.axvspan(lo, hi, color="0.94" if number % 2 else "white", zorder=0)
        width = max(8, int(16 * (hi - lo)))
        ax.text(
            (lo + hi) / 2,
            1.01,
            textwrap.fill(mechanism, width),
            transform=ax.get_xaxis_transform(),
            ha="center",
            va="bottom",
            fontsize=5.5,
        )


def _draw_chain(ax, rows: pd.DataFrame, position: dict, shift, n_beads, marker, color) -> None:
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
        color=color,
        capsize=2,
        label=f"N = {n_beads}",
    )
    # "n/r" of the two chains one above the other.
    for xi, value in zip(x, rows["ssw_over_Fm"]):
        if not math.isfinite(float(value)):
            ax.text(
                xi,
                0.02 + 0.05 * (marker == "x"),
                "n/r",
                transform=ax.get_xaxis_transform(),
                ha="center",
                fontsize=5,
                color=color,
            )
