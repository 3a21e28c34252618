"""The sweep table: one row per simulated model and chain, C and the SSW slope side by side.

A sweep run (``whatif/sweep.yaml``: N over a range, even and odd, and three
Kuwabara-Kono relaxation times eta) is read as C(N) and SSW(N). The numbers are the
ones already fitted in ``delay_fits.csv`` (C of |Delta| = C F_m^(-1/6), free exponent)
and ``ssw_fits.csv`` (SSW amplitude / F_m); this module only joins them with each
model's eta from the config, so that a user (or a spreadsheet) has one table.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

#: Columns of ``tables/sweep.csv``, in order.
SWEEP_COLUMNS = tuple(
    "model eta_s N parity C_us_N16 C_stderr_us_N16 exponent exponent_stderr n_delays "
    "ssw_slope ssw_slope_stderr n_ssw".split()
)
#: The SSW measurement taken from ``ssw_fits.csv`` when it holds several.
SSW_METHOD = "residual"


def sweep_table(
    delay_fits: pd.DataFrame, ssw_fits: pd.DataFrame, eta_s: Mapping[str, float], estimator: str
) -> pd.DataFrame:
    """C(N) and SSW slope(N) of every simulated model, one row per model and chain.

    Parameters
    ----------
    delay_fits : DataFrame
        ``delay_fits.csv`` (source, model, N, estimator, C_us_N16, ...).
    ssw_fits : DataFrame
        ``ssw_fits.csv`` (source, model, N, slope, slope_stderr, n_points[, method]).
    eta_s : mapping
        Kuwabara-Kono relaxation time of each model name, s.
    estimator : str
        Pulse estimator whose delay fits are used (the run's main estimator).

    Returns
    -------
    DataFrame
        :data:`SWEEP_COLUMNS`, sorted by eta, model and N; ``parity`` is ``even``
        (the waves meet at a contact) or ``odd`` (at a bead). A chain with no SSW fit
        has NaN there. Pooled fits and experiment rows are left out.
    """
    delays = _per_chain(delay_fits)
    delays = delays[delays["estimator"] == estimator]
    ssw = _per_chain(ssw_fits)
    if "method" in ssw.columns and (ssw["method"] == SSW_METHOD).any():
        ssw = ssw[ssw["method"] == SSW_METHOD]
    ssw = ssw.rename(
        columns={"slope": "ssw_slope", "slope_stderr": "ssw_slope_stderr", "n_points": "n_ssw"}
    )
    table = delays.rename(columns={"n_points": "n_delays"}).merge(
        ssw[["model", "N", "ssw_slope", "ssw_slope_stderr", "n_ssw"]], on=["model", "N"], how="left"
    )
    table["eta_s"] = table["model"].map(lambda name: eta_s.get(name, float("nan")))
    table["parity"] = ["even" if n % 2 == 0 else "odd" for n in table["N"]]
    table = table.sort_values(["eta_s", "model", "N"], kind="stable", ignore_index=True)
    return table[list(SWEEP_COLUMNS)]


def _per_chain(fits: pd.DataFrame) -> pd.DataFrame:
    """Simulation rows of one chain each (not ``pooled``), N as int."""
    rows = fits[(fits["source"] == "simulation") & (fits["N"].astype(str) != "pooled")].copy()
    rows["N"] = rows["N"].astype(int)
    return rows
