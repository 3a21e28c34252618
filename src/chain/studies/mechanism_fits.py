"""What the mechanism study measures of a series: C of Delta = C F_m^(-1/6) and the
SSW/F_m slope at S2 (the SSW behind the LSTW), analysed as every other series.

The pulses, delays and their fits follow the pipeline's recipe
(:mod:`chain.analysis.recipe`); the SSW are read at S2 with
:func:`chain.analysis.ssw.ssw_table` and fitted with
:func:`chain.analysis.ssw.ssw_fit_table`.
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd

from chain.analysis.pulse_rows import pulse_table
from chain.analysis.recipe import fit_pulses
from chain.analysis.ssw import ssw_fit_table, ssw_table


def analyse_traces(traces: pd.DataFrame, estimator: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """C and the SSW slope at S2 of one trace table, as the pipeline analyses any series:
    (:func:`chain.analysis.recipe.fit_pulses` rows, per N and pooled;
    :func:`chain.analysis.ssw.ssw_fit_table` rows of the S2 readings, SSW behind LSTW).

    Parameters
    ----------
    traces : DataFrame
        A trace table (collision and reference shots per amplitude).
    estimator : str
        Pulse estimator (:data:`chain.analysis.pulses.ESTIMATORS`).
    """
    pulses = pulse_table(traces, estimators=(estimator,))
    ssw = ssw_table(traces, pulses, estimator=estimator)
    return fit_pulses(pulses), ssw_fit_table(ssw[ssw["sensor"] == "S2"])


def analyse_per_estimator(
    traces: pd.DataFrame, estimators: Sequence[str]
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """:func:`analyse_traces` with each estimator, one after the other, rows tagged with
    it in an ``estimator`` column (:func:`chain.analysis.rows.of_estimator` picks one).

    Parameters
    ----------
    traces : DataFrame
        A trace table (collision and reference shots per amplitude).
    estimators : sequence of str
        Pulse estimators (:data:`chain.analysis.pulses.ESTIMATORS`).
    """
    delay_fits, ssw_fits = [], []
    for estimator in estimators:
        delays, ssw = analyse_traces(traces, estimator)
        delay_fits.append(delays.assign(estimator=estimator))
        ssw_fits.append(ssw.assign(estimator=estimator))
    return pd.concat(delay_fits, ignore_index=True), pd.concat(ssw_fits, ignore_index=True)
