"""Fig. 3: simulated forces felt by the sensor beads (the sensors are not modelled).

The panels are drawn by :mod:`chain.report.figures.trace_panels`, shared with Fig. 2.
"""

from __future__ import annotations

import pandas as pd
from matplotlib.figure import Figure

from chain.report.figures.trace_panels import trace_figure


def fig3_simulation_traces(
    traces,
    pulses: pd.DataFrame | None = None,
    ssw: pd.DataFrame | None = None,
    *,
    model: str | None = "viscoelastic",
    representative_force_N: float = 300.0,
    representative_index: int | None = None,
    estimator: str = "fit_full",
    label: str = "simulation",
    inset: bool = True,
) -> Figure:
    """Fig. 3: simulated forces felt by the sensor beads (sensors not modelled).

    One column per chain (paper: (A, B) N = 25 at n = 9, 17; (C, D) N = 26 at
    n = 10, 17), drawn as :mod:`chain.report.figures.trace_panels` describes; the SSW
    amplitude from ``ssw`` is marked in the inset.

    Parameters
    ----------
    traces : DataFrame or sequence of DataFrames
        Trace tables (one chain each, or several chains in one table).
    pulses : DataFrame, optional
        ``pulses.csv``: pulse times for the split and the incident F_m used to pick the
        representative amplitude (without it: the peak of the S1 trace).
    ssw : DataFrame, optional
        ``ssw.csv``: the SSW marked in the insets.
    model : str or None
        Model to show (None: the first in the table).
    representative_force_N : float
        Show the amplitude whose incident F_m at S1 is closest to this, N.
    representative_index : int, optional
        Show this amplitude index instead.
    estimator : str
        Estimator whose pulse times and amplitudes are used.
    label : str
        Name of the data in the title.
    inset : bool
        Draw the SSW zoom.
    """
    return trace_figure(
        traces,
        pulses,
        ssw,
        source="simulation",
        model=model,
        representative_force_N=representative_force_N,
        representative_index=representative_index,
        estimator=estimator,
        title=f"{label}: forces felt by the sensor beads (sensors not modelled)",
        inset=inset,
    )
