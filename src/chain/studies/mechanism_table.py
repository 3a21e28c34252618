"""The mechanism study's table (``tables/ssw_mechanisms.csv``): SSW/F_m at S2 and C
per mechanism and setting, each against its reference (the frictionless LAMMPS setting,
or the virtual experiment as configured).

The fits come from :mod:`chain.studies.mechanism_fits` (the LAMMPS settings and the
ablation variants that are candidates); this module only tabulates them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from chain.labels import REFERENCE_MECHANISM

#: Columns of ``tables/ssw_mechanisms.csv`` (the results contract).
MECHANISM_COLUMNS = tuple(
    "mechanism setting N ssw_over_Fm ssw_over_Fm_err ratio_to_frictionless C C_stderr".split()
)


def mechanism_rows(
    mechanism: str,
    settings: Mapping[str, str],
    delay_fits: Sequence[pd.DataFrame],
    ssw_fits: Sequence[pd.DataFrame],
    reference: str,
) -> pd.DataFrame:
    """Rows of ``ssw_mechanisms.csv`` for one mechanism.

    Parameters
    ----------
    mechanism : str
        The ``mechanism`` column.
    settings : mapping
        Series name (the ``model`` column of the fits) -> setting label.
    delay_fits, ssw_fits : sequence of DataFrame
        :func:`chain.studies.mechanism_fits.analyse_traces` outputs of every series and chain.
    reference : str
        The series name of the frictionless (or ingredient-off) reference: its SSW/F_m
        per N is the denominator of ``ratio_to_frictionless``.

    Returns
    -------
    DataFrame
        Columns :data:`MECHANISM_COLUMNS`, one row per (setting, N), the reference's
        rows first (if it is one of ``settings``); SSW/F_m is the
        proportional slope of SSW against F_m at S2 (N/N) and its standard error, C in
        us N^(1/6).
    """
    delays = pd.concat(delay_fits, ignore_index=True)
    delays = delays[delays["N"].astype(str) != "pooled"].astype({"N": int})
    ssw = pd.concat(ssw_fits, ignore_index=True).astype({"N": int})
    base = ssw[ssw["model"] == reference].set_index("N")["slope"]
    rows = []
    ssw = ssw.assign(_first=ssw["model"] != reference).sort_values("_first", kind="stable")
    for (model, n_beads), group in ssw.groupby(["model", "N"], sort=False):
        if model not in settings:
            continue
        fit = group.iloc[0]
        delay = delays[(delays["model"] == model) & (delays["N"] == n_beads)]
        c_row = delay.iloc[0] if len(delay) else None
        rows.append(
            {
                "mechanism": mechanism,
                "setting": settings[model],
                "N": int(n_beads),
                "ssw_over_Fm": float(fit["slope"]),
                "ssw_over_Fm_err": float(fit["slope_stderr"]),
                "ratio_to_frictionless": float(fit["slope"]) / float(base.get(n_beads, np.nan)),
                "C": np.nan if c_row is None else float(c_row["C_us_N16"]),
                "C_stderr": np.nan if c_row is None else float(c_row["C_stderr_us_N16"]),
            }
        )
    return pd.DataFrame(rows, columns=MECHANISM_COLUMNS)


def candidate_rows(
    candidates: Mapping[str, tuple[str, str]],
    delay_fits: pd.DataFrame,
    ssw_fits: pd.DataFrame,
    reference: str,
) -> pd.DataFrame:
    """Rows of ``ssw_mechanisms.csv`` for the virtual-experiment candidates (ablation
    variants with a ``mechanism``), each against the ``reference`` variant.

    Parameters
    ----------
    candidates : mapping
        Variant name -> (mechanism, setting label); the reference may be absent.
    delay_fits, ssw_fits : DataFrame
        :func:`chain.studies.ablation.run_variants`'s, of every variant (replicate 0 used).
    reference : str
        Name of the reference variant (the run's virtual experiment).

    Returns
    -------
    DataFrame
        Columns :data:`MECHANISM_COLUMNS`: the reference first (ratio 1), then every
        candidate in order.
    """

    def first(table: pd.DataFrame, name: str) -> pd.DataFrame:
        return table[(table["variant"] == name) & (table["replicate"] == 0)].assign(model=name)

    groups = {REFERENCE_MECHANISM: {reference: "as configured"}}
    for name, (mechanism, label) in candidates.items():
        if name != reference:
            groups.setdefault(mechanism, {})[name] = label
    names = [reference, *(n for n in candidates if n != reference)]
    delays = [first(delay_fits, n) for n in names]
    ssw = [first(ssw_fits, n) for n in names]
    tables = [
        mechanism_rows(mechanism, settings, delays, ssw, reference)
        for mechanism, settings in groups.items()
    ]
    return pd.concat(tables, ignore_index=True)
