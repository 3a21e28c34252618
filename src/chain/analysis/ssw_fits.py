"""SSW fits: SSW = slope x F_m per series and chain with a statistical and a systematic
error, whether the SSW is resolved at each sensor, and the even / odd ratio of the
slopes. Reads ``ssw.csv`` rows (:func:`chain.analysis.ssw.ssw_table`); computes no SSW."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.analysis.regression import fit_proportional, ratio_with_error
from chain.analysis.rows import is_ok

#: Columns of :func:`ssw_fit_table`.
SSW_FIT_COLUMNS = tuple(
    "source model N slope slope_stderr slope_stat slope_sys n_points n_resolved method".split()
)


def ssw_fit_table(ssw: pd.DataFrame, method: str = "residual") -> pd.DataFrame:
    """SSW = slope x F_m through the origin, per source, model and N (``ssw_fits.csv``).

    Every measurable (``ok``) row of ``method``, upper limits included at their values,
    weighted by 1 / ``ssw_err_N``^2 (:func:`proportional_slope`). Fewer than 2 points
    give NaN and ``n_points``.

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv`` rows (:func:`ssw_table`).
    method : {"residual", "peak"}
        Which SSW measurement to fit.

    Returns
    -------
    DataFrame
        Columns :data:`SSW_FIT_COLUMNS`; slopes in N/N, ``n_resolved`` the fitted rows
        that are resolved (the strict rule).
    """
    rows = []
    chosen = ssw[ssw["method"] == method]
    for (source, model, n_beads), group in chosen.groupby(["source", "model", "N"], sort=True):
        used = group[is_ok(group)]
        fit = proportional_slope(
            used["F_m_N"].to_numpy(float),
            used["ssw_N"].to_numpy(float),
            used["ssw_err_N"].to_numpy(float),
            used["ssw_sys_N"].to_numpy(float),
        )
        resolved = used["resolved"].astype(bool) if "resolved" in used else used["ok"]
        rows.append(
            {"source": source, "model": model, "N": int(n_beads), "method": method}
            | fit
            | {"n_resolved": int(resolved.sum())}
        )
    return pd.DataFrame(rows, columns=SSW_FIT_COLUMNS)


def proportional_slope(force_N, value_N, error_N, systematic_N) -> dict:
    """Slope of value = slope x force through the origin, with two errors.

    Weighted least squares (weights 1 / error^2; unweighted where any error is not
    positive). ``slope_stat``: the fit's standard error from the scatter of the points
    (scaled by the reduced chi-square, so it measures how well they lie on a line
    through the origin). ``slope_sys``: how far the slope moves when every value is
    shifted by its systematic error (same weights). ``slope_stderr``: both in quadrature.

    Parameters
    ----------
    force_N, value_N : array
        Incident amplitudes and SSW values, N.
    error_N : array
        Total error of each value, N.
    systematic_N : array
        Systematic error of each value, N.

    Returns
    -------
    dict
        ``slope``, ``slope_stat``, ``slope_sys``, ``slope_stderr`` (N/N), ``n_points``.
    """
    error = np.asarray(error_N, dtype=float)
    sigma = error if error.size and np.all(error > 0) else None
    fit = fit_proportional(force_N, value_N, sigma)
    shifted = fit_proportional(force_N, np.asarray(value_N) + np.asarray(systematic_N), sigma)
    systematic = abs(shifted.coefficient - fit.coefficient)
    return {
        "slope": fit.coefficient,
        "slope_stderr": math.hypot(fit.stderr, systematic),
        "slope_stat": fit.stderr,
        "slope_sys": systematic,
        "n_points": fit.n_points,
    }


#: Columns of :func:`ssw_resolution_table` (summary key ``ssw_resolved``).
RESOLUTION_COLUMNS = ("source", "model", "N", "sensor", "resolved", "n_resolved", "n_total")


def ssw_resolution_table(ssw: pd.DataFrame, method: str = "residual") -> pd.DataFrame:
    """Is the SSW resolved at each sensor? One row per (source, model, N, sensor).

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv`` rows (:func:`ssw_table`).
    method : {"residual", "peak"}
        Which measurement's rows to count.

    Returns
    -------
    DataFrame
        Columns :data:`RESOLUTION_COLUMNS`: ``n_resolved`` of ``n_total`` collision shots
        have a value (``ok``); ``resolved`` is True when at least half of them do.
    """
    rows = []
    chosen = ssw[ssw["method"] == method]
    for key, group in chosen.groupby(["source", "model", "N", "sensor"], sort=True):
        n_resolved, n_total = int(group["resolved"].astype(bool).sum()), len(group)
        rows.append(
            dict(zip(RESOLUTION_COLUMNS[:4], key))
            | {"resolved": n_total > 0 and 2 * n_resolved >= n_total}
            | {"n_resolved": n_resolved, "n_total": n_total}
        )
    table = pd.DataFrame(rows, columns=RESOLUTION_COLUMNS)
    table["N"] = table["N"].astype(int)
    return table


def ssw_parity_table(fits: pd.DataFrame, even: int = 26, odd: int = 25) -> pd.DataFrame:
    """SSW slope of the even chain over the odd one's, per source and model (the paper's
    claim: larger when the waves cross at a contact). NaN where either has no fit.

    Parameters
    ----------
    fits : DataFrame
        ``ssw_fits.csv`` rows (:func:`ssw_fit_table`).
    even, odd : int
        The two chains compared (the paper's 26 and 25).

    Returns
    -------
    DataFrame
        ``source, model, ratio, ratio_err`` for every (source, model) with both chains;
        ``ratio_err`` from the two slopes' ``slope_stderr`` in quadrature (relative),
        NaN where a fit has none.
    """
    rows = []
    numeric = fits[fits["N"].astype(str).isin([str(even), str(odd)])]
    for (source, model), group in numeric.groupby(["source", "model"], sort=True):
        by_n = {int(row.N): row for row in group.itertuples(index=False)}
        if even in by_n and odd in by_n:
            rows.append(
                {"source": source, "model": model}
                | ratio_with_error(
                    by_n[even].slope,
                    getattr(by_n[even], "slope_stderr", math.nan),
                    by_n[odd].slope,
                    getattr(by_n[odd], "slope_stderr", math.nan),
                )
            )
    return pd.DataFrame(rows, columns=["source", "model", "ratio", "ratio_err"])
