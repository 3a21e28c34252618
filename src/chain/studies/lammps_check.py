"""The LAMMPS cross-check of the mechanism study (``tables/lammps_check.csv``).

In the frictionless 1D limit (no track, no gravity, mu = 0) LAMMPS
(:mod:`chain.physics.lammps_engine`, optional) and our kernel
(:func:`chain.physics.simulation.simulate`) run the same shots; their sensor traces and
their C must agree. This module maps config keys and knows no Snakemake.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from chain.apparatus.lammps_shots import lammps_shots
from chain.apparatus.shots import shot_time_step, simulate_shots
from chain.physics.builders import uniform_chain
from chain.physics.materials import get_material
from chain.studies.mechanism_fits import analyse_traces
from chain.studies.mechanism_settings import granular_chain

#: Columns of ``tables/lammps_check.csv``.
CHECK_COLUMNS = tuple(
    "N model eta_s n_speeds C_kernel C_kernel_stderr C_lammps rel_diff_C "
    "max_trace_diff_over_Fm max_trace_diff_N dt_kernel_s dt_lammps_s within_tolerance".split()
)

#: The cross-check's targets: C within this relative difference, and every sensor
#: sample within this fraction of the shot's F_m.
C_TOLERANCE = 1e-4
TRACE_TOLERANCE = 1e-4


def trace_difference(first: pd.DataFrame, second: pd.DataFrame) -> tuple[float, float]:
    """Largest |difference| of two trace tables with the same shots, sensors and sample
    times, sample by sample: (over the shot's F_m, in N). F_m of a shot is its largest
    sensor force in ``first``."""
    columns = [c for c in first.columns if c.startswith("force_bead")]
    worst_ratio, worst = 0.0, 0.0
    for shot, group in first.groupby("shot", sort=True):
        other = second[second["shot"] == shot]
        samples = min(len(group), len(other))
        a = group[columns].to_numpy(float)[:samples]
        b = other[columns].to_numpy(float)[:samples]
        diff = float(np.max(np.abs(a - b)))
        worst = max(worst, diff)
        worst_ratio = max(worst_ratio, diff / float(np.max(np.abs(a))))
    return worst_ratio, worst


def check_row(
    kernel: pd.DataFrame, lammps: pd.DataFrame, *, estimator: str, model: str, eta: float
) -> dict:
    """One row of ``lammps_check.csv`` from the kernel's and LAMMPS' traces of the same
    shots (one chain, one model); ``dt_*`` columns are left to the caller."""
    c_kernel = _c_of(analyse_traces(kernel, estimator)[0])
    c_lammps = _c_of(analyse_traces(lammps, estimator)[0])
    ratio, worst = trace_difference(kernel, lammps)
    rel = abs(c_lammps[0] - c_kernel[0]) / c_kernel[0]
    return {
        "N": int(kernel["N"].iloc[0]),
        "model": model,
        "eta_s": eta,
        "n_speeds": int(kernel["amplitude"].nunique()),
        "C_kernel": c_kernel[0],
        "C_kernel_stderr": c_kernel[1],
        "C_lammps": c_lammps[0],
        "rel_diff_C": rel,
        "max_trace_diff_over_Fm": ratio,
        "max_trace_diff_N": worst,
        "within_tolerance": bool(rel <= C_TOLERANCE and ratio <= TRACE_TOLERANCE),
    }


def _c_of(fits: pd.DataFrame) -> tuple[float, float]:
    """(C, its standard error) of the single chain in ``fits``, us N^(1/6)."""
    row = fits[fits["N"].astype(str) != "pooled"].iloc[0]
    return float(row["C_us_N16"]), float(row["C_stderr_us_N16"])


def run_lammps_check(config: Mapping, estimators: Sequence[str]) -> pd.DataFrame:
    """The cross-check of every configured chain and model (``lammps_check.csv``), with
    each estimator.

    For each chain (N, sensors) and model (eta): the same collision and reference shots
    at ``lammps.check_speeds_m_s`` by our kernel (its default step) and by LAMMPS
    without track, gravity or friction; rows as :func:`check_row`.

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    estimators : sequence of str
        Pulse estimators of the C fits.

    Returns
    -------
    DataFrame
        :data:`CHECK_COLUMNS`, then ``estimator``: one row per chain, model and
        estimator (``chain.analysis.rows.picked`` gives one estimator's table).
    """
    options = config["lammps"]
    speeds = options["check_speeds_m_s"]
    material = get_material(config["material"])
    rows = []
    for entry in config["chains"]:
        n_beads, sensors = int(entry["N"]), entry["sensors"]
        for model in config["models"]:
            eta = float(model["eta_s"])
            chain = uniform_chain(n_beads, material, config["radius_m"], eta)
            kernel, _ = simulate_shots(
                chain,
                speeds,
                sensors,
                model_name=model["name"],
                duration=options["duration_s"],
                record_interval=options["record_interval_s"],
            )
            lammps, _ = lammps_shots(
                granular_chain(config, n_beads, eta=eta),
                speeds,
                sensors,
                model_name=model["name"],
                duration=options["duration_s"],
                dt=options["time_step_s"],
                record_interval=options["record_interval_s"],
            )
            dt_kernel = shot_time_step(chain, speeds, None, options["record_interval_s"])
            for estimator in estimators:
                row = check_row(kernel, lammps, estimator=estimator, model=model["name"], eta=eta)
                row["dt_kernel_s"] = dt_kernel
                row["dt_lammps_s"] = options["time_step_s"]
                rows.append({**row, "estimator": estimator})
    return pd.DataFrame(rows, columns=[*CHECK_COLUMNS, "estimator"])
