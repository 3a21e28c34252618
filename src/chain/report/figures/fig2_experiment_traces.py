"""Fig. 2: experiment forces at the sensor beads, (A, B) N = 25, (C, D) N = 26: the
panels of Fig. 3 (:mod:`chain.report.figures.trace_panels`) for a collision shot that
the acceptance protocol kept."""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from chain.report.figures.trace_panels import trace_figure


def fig2_experiment_traces(
    traces,
    pulses: pd.DataFrame | None = None,
    ssw: pd.DataFrame | None = None,
    *,
    model: str | None = None,
    representative_force_N: float = 300.0,
    representative_index: int | None = None,
    estimator: str = "fit_full",
    label: str = "experiment",
    inset: bool = True,
    selection: pd.DataFrame | None = None,
) -> Figure:
    """Fig. 2: experiment forces at S1 and S2, (A, B) N = 25, (C, D) N = 26.

    Parameters as in
    :func:`chain.report.figures.fig3_simulation_traces.fig3_simulation_traces`;
    ``traces`` are experiment trace tables (virtual or measured) and ``label`` names
    them. ``selection``: ``experiment/selection.csv``
    (:func:`chain.analysis.selection.select_shots`): the collision shot drawn is the
    first one the acceptance protocol kept, from the amplitudes that have one (None:
    the first collision shot).
    """
    return trace_figure(
        traces,
        pulses,
        ssw,
        source="experiment",
        model=model,
        representative_force_N=representative_force_N,
        representative_index=representative_index,
        estimator=estimator,
        title=f"{label}: forces at the sensor beads",
        inset=inset,
        selection=selection,
    )
