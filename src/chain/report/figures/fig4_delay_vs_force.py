"""Fig. 4: the crossing delay |Delta| against the incident amplitude F_m (log-log)."""

from __future__ import annotations

from collections.abc import Mapping

import matplotlib as mpl
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from chain.analysis.rows import usable_rows
from chain.report.figures import picks
from chain.report.figures.style import (
    STYLE,
    add_legend,
    axes_or_new,
    chain_marker,
    model_colors,
    plain_log_ticks,
    plain_numbers,
    us_n16,
)
from chain.report.naming import series_name
from chain.report.numbers.paper import PAPER
from chain.report.printed import plus_minus


def fig4_delay_vs_force(
    delays: pd.DataFrame,
    fits: pd.DataFrame | None = None,
    *,
    constants: Mapping | None = None,
    estimator: str = "fit_full",
    experiment_label: str = "experiment",
    paper: Mapping = PAPER,
    ax=None,
) -> Figure:
    """Fig. 4: crossing delay |Delta| against the incident amplitude F_m (log-log).

    Simulation: a solid line per model and chain (mean of LSTW and RSTW per launch)
    and the fitted Delta = C F_m^(-1/6) of each model (chains pooled), dashed, with C
    in the legend. Experiment rows (if any): N = 25 open circles, N = 26 crosses, and
    their own pooled fit. For comparison, the ballistic predictions (Eq. 6 as printed,
    and with the exact Hertz contact time) and the paper's C_exp.

    Parameters
    ----------
    delays : DataFrame
        ``delays.csv``.
    fits : DataFrame, optional
        ``delay_fits.csv``.
    constants : mapping, optional
        ``C_bal_paper_us_N16`` and ``C_bal_exact_us_N16`` of this run's beads
        (:func:`chain.physics.theory.ballistic_constants`), µs N^(1/6).
    estimator : str
        Estimator drawn.
    experiment_label : str
        Name of ``source == "experiment"`` rows.
    paper : mapping
        The paper's numbers (``C_exp_us_N16``, ``C_exp_err_us_N16``, ``C_bal_us_N16``).
    ax : Axes, optional
        Draw here instead of on a new figure.
    """
    own = ax is None
    fig, ax = axes_or_new(ax, 6.4, 5.4)
    rows = delays[delays["estimator"] == estimator].copy()
    rows["abs_delay_us"] = pd.to_numeric(rows["delay_us"], errors="coerce").abs()
    rows = usable_rows(rows, ["F_m_N", "abs_delay_us"], f"Fig. 4 ({estimator})", positive=True)
    per_chain = picks.experiment_chain_fits(fits, estimator)
    colors = model_colors(picks.simulated_models(rows))
    with mpl.rc_context(STYLE):
        low, high = _plot_simulation(ax, rows[rows["source"] == "simulation"], colors)
        experiment = rows[rows["source"] == "experiment"]
        all_n = sorted({int(n) for n in rows["N"]})
        low_e, high_e = _plot_experiment(ax, experiment, all_n, per_chain, experiment_label)
        force_range = [min(low, low_e), max(high, high_e)]
        if not np.all(np.isfinite(force_range)):
            force_range = [10.0, 1000.0]
        grid = np.geomspace(force_range[0], force_range[1], 50)
        if fits is not None and len(fits):
            _plot_fits(ax, grid, picks.pooled_fits(fits, estimator), colors, experiment_label)
        for value, color, style, label in _reference_lines(constants, paper):
            ax.plot(grid, value * grid ** (-1 / 6), color=color, ls=style, lw=1.0, label=label)
        _style_axes(ax, estimator)
        add_legend(fig, ax, own, "lower left")
    return fig


def _plot_simulation(ax, simulation, colors) -> tuple[float, float]:
    """A line per model and chain: |Delta| and F_m averaged over the two waves of each
    launch amplitude. Returns the range of F_m drawn, N."""
    low, high = np.inf, -np.inf
    for (model, n), group in simulation.groupby(["model", "N"], sort=False):
        mean = group.groupby("amplitude")[["F_m_N", "abs_delay_us"]].mean().sort_values("F_m_N")
        ax.plot(
            mean["F_m_N"],
            mean["abs_delay_us"],
            color=colors[model],
            ls="-",
            lw=1.0 if int(n) % 2 else 1.6,
            marker="o" if int(n) % 2 else "s",
            ms=2.5,
            alpha=0.9,
            label=f"simulation, {model}, N = {int(n)}",
        )
        low, high = min(low, mean["F_m_N"].min()), max(high, mean["F_m_N"].max())
    return low, high


def _plot_experiment(ax, experiment, all_n, per_chain, experiment_label) -> tuple[float, float]:
    """Open black markers per series and chain, the chain's own fit in the legend.
    Returns the range of F_m drawn, N."""
    low, high = np.inf, -np.inf
    for (model, n), group in experiment.groupby(["model", "N"], sort=True):
        label = series_name("experiment", model, experiment_label, int(n))
        if (model, int(n)) in per_chain:
            c, err = per_chain[(model, int(n))]
            label += f" (own fit C = {plus_minus(c, err, 1, style='mathtext')})"
        ax.plot(
            group["F_m_N"],
            group["abs_delay_us"],
            ls="none",
            marker=chain_marker(int(n), all_n),
            mfc="none",
            mec="black",
            color="black",
            ms=5,
            mew=0.9,
            label=label,
        )
        low, high = min(low, group["F_m_N"].min()), max(high, group["F_m_N"].max())
    return low, high


def _plot_fits(ax, grid, pooled, colors, experiment_label) -> None:
    """The pooled fits Delta = C F_m^(-1/6), dashed, with C in the legend."""
    for fit in pooled:
        who = f"fit to {series_name(fit.source, fit.model, experiment_label)}"
        who += ", N pooled" if fit.source == "experiment" else ""
        color = "black" if fit.source == "experiment" else colors.get(fit.model, "grey")
        ax.plot(
            grid,
            fit.C_us_N16 * grid ** (-1 / 6),
            color=color,
            ls="--",
            lw=1.0,
            label=f"{who}: C = {plus_minus(fit.C_us_N16, fit.C_stderr_us_N16, 1, style='mathtext')}"
            " µs N$^{1/6}$",
        )


def _reference_lines(constants, paper) -> list[tuple]:
    """(C µs N^(1/6), colour, dash, label) of the ballistic predictions (when
    ``constants`` are given) and of the paper's experimental fit."""
    references = []
    if constants is not None:
        paper_c, exact_c = constants["C_bal_paper_us_N16"], constants["C_bal_exact_us_N16"]
        references += [
            (
                paper_c,
                "#555555",
                (0, (6, 2, 1, 2)),
                "ballistic, Eq. 6 as printed: C$_{bal}$ = " + us_n16(paper_c),
            ),
            (
                exact_c,
                "#999999",
                (0, (3, 1.5)),
                "ballistic, exact Hertz contact time: " + us_n16(exact_c),
            ),
        ]
    references.append(
        (
            paper["C_exp_us_N16"],
            "#6a3d9a",
            (0, (1, 1.5)),
            "paper's experimental fit: C$_{exp}$ = "
            + plus_minus(paper["C_exp_us_N16"], paper["C_exp_err_us_N16"], 1, style="mathtext")
            + " µs N$^{1/6}$",
        )
    )
    return references


def _style_axes(ax, estimator: str) -> None:
    ax.set_xscale("log")
    ax.set_yscale("log")
    plain_log_ticks(ax.yaxis)
    plain_numbers(ax.xaxis)
    ax.set_xlabel("incident amplitude F$_m$ at the first sensor (N)")
    ax.set_ylabel("|Δ| = |TOF(crossed) − TOF(reference)| (µs)")
    ax.set_title(f"Crossing delay against amplitude ({estimator} estimator)", loc="left")
