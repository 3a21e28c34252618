"""The analysis recipe of every series: pulses -> delays -> fits of Delta = C F_m^(-1/6).

The paper run takes these steps in separate jobs (``pulses.csv``, ``delays.csv``,
``delay_fits.csv``); the studies take them in-process. Both go through this module, so
that the row policy and the fits are written once and reach every table alike.
"""

from __future__ import annotations

import pandas as pd

from chain.analysis.delays import delay_fit_table, delay_table
from chain.analysis.rows import flag_unusable


def fit_delays(delays: pd.DataFrame) -> pd.DataFrame:
    """Fits of |Delta| against F_m of a delay table, with the pipeline's row policy.

    Rows a fit cannot use (flagged ``ok`` False, or NaN/inf in ``F_m_N`` or
    ``delay_us``) are flagged ``ok`` False first, their count going to the log
    (:func:`chain.analysis.rows.flag_unusable`): :func:`chain.analysis.delays.delay_fit_table`
    refuses a NaN in an ``ok`` row.

    Parameters
    ----------
    delays : DataFrame
        Delay rows (:func:`chain.analysis.delays.delay_table`; ``delays.csv``): F_m in
        N, Delta in us.

    Returns
    -------
    DataFrame
        :data:`chain.analysis.delays.DELAY_FIT_COLUMNS` rows (``delay_fits.csv``): per
        chain and pooled, C in us N^(1/6) and the free exponent.
    """
    return delay_fit_table(flag_unusable(delays, ["F_m_N", "delay_us"], "delay rows"))


def fit_pulses(pulses: pd.DataFrame, selection: pd.DataFrame | None = None) -> pd.DataFrame:
    """Pulses -> delays -> fits: :func:`chain.analysis.delays.delay_table` of the
    selected collision shots, then :func:`fit_delays` (whose rows it returns).

    Parameters
    ----------
    pulses : DataFrame
        Pulse rows (:func:`chain.analysis.pulse_rows.pulse_table`) of collision and
        reference shots; several chains and estimators may share the table.
    selection : DataFrame or None
        The acceptance protocol's shot selection
        (:func:`chain.analysis.selection.select_shots`); None keeps every shot.
    """
    return fit_delays(delay_table(pulses, selection=selection))
