"""The ablation table (``tables/ablation_exponent.csv``): C and the free exponent of
every variant of the virtual experiment, at the run's seed and over the seeds of its
replicates, tabulated from their fits (:func:`chain.studies.ablation.run_variants`)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from chain.labels import VIRTUAL_LABEL

#: Columns of :func:`ablation_table`, in order (after ``exponent_stderr``: extras).
ABLATION_COLUMNS = tuple(
    "variant N C C_stderr exponent exponent_stderr n_points estimator n_seeds C_seed_mean "
    "C_seed_std exponent_seed_mean exponent_seed_std series overrides".split()
)


def ablation_table(fits: Mapping[str, pd.DataFrame], overrides: Mapping[str, str]) -> pd.DataFrame:
    """Rows of ``ablation_exponent.csv`` from the fits of every variant.

    Parameters
    ----------
    fits : mapping
        Variant name -> its fits (:func:`chain.studies.ablation.run_variants` rows with
        ``estimator`` and ``replicate``; replicate 0 is the run's seed).
    overrides : mapping
        Variant name -> its overrides as text (for the ``overrides`` column).

    Returns
    -------
    DataFrame
        Columns :data:`ABLATION_COLUMNS`: C (us N^1/6) and the free exponent with their
        standard errors at the run's seed per N and pooled, and the mean and standard
        deviation over the seeds of the replicates.
    """
    rows = []
    for name, table in fits.items():
        for (n_beads, estimator), group in table.groupby(["N", "estimator"], sort=False):
            first = group[group["replicate"] == 0].iloc[0]
            c = group["C_us_N16"].to_numpy(dtype=float)
            p = group["exponent"].to_numpy(dtype=float)
            many = len(group) > 1
            rows.append(
                {
                    "variant": name,
                    "N": n_beads,
                    "C": first["C_us_N16"],
                    "C_stderr": first["C_stderr_us_N16"],
                    "exponent": first["exponent"],
                    "exponent_stderr": first["exponent_stderr"],
                    "n_points": first["n_points"],
                    "estimator": estimator,
                    "n_seeds": len(group),
                    "C_seed_mean": float(np.mean(c)),
                    "C_seed_std": float(np.std(c, ddof=1)) if many else float("nan"),
                    "exponent_seed_mean": float(np.mean(p)),
                    "exponent_seed_std": float(np.std(p, ddof=1)) if many else float("nan"),
                    "series": VIRTUAL_LABEL,
                    "overrides": overrides.get(name, ""),
                }
            )
    return pd.DataFrame(rows, columns=ABLATION_COLUMNS)


def overrides_text(variant: Mapping) -> str:
    """A variant's overrides as ``key=value; ...`` (``none`` for the run as configured)."""
    return "; ".join(f"{k}={v}" for k, v in variant["set"].items()) or "none"
