"""The sweep table (chain.pipeline.sweep) and its C(N) figure (chain.report.fig_c_vs_N)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.pipeline.sweep import SWEEP_COLUMNS, sweep_table
from chain.report.fig_c_vs_N import fig_c_vs_N

ETA = {"elastic": 0.0, "viscoelastic": 0.58e-6}


def delay_fits():
    rows = []
    for model, base in (("elastic", 38.0), ("viscoelastic", 41.0)):
        for n in (20, 21, 22):
            for estimator, shift in (("fit_full", 0.0), ("peak", 5.0)):
                rows.append(
                    {
                        "source": "simulation",
                        "model": model,
                        "N": str(n),
                        "estimator": estimator,
                        "C_us_N16": base + 0.1 * n + shift,
                        "C_stderr_us_N16": 0.01 * n,
                        "exponent": -1 / 6,
                        "exponent_stderr": 1e-4,
                        "n_points": 12,
                    }
                )
        rows.append({**rows[-1], "N": "pooled", "C_us_N16": 99.0})
    rows.append({**rows[0], "source": "experiment", "model": "virtual", "C_us_N16": 77.0})
    return pd.DataFrame(rows)


def ssw_fits():
    rows = [
        {
            "source": "simulation",
            "model": model,
            "N": n,
            "slope": (0.04 if n % 2 == 0 else 0.02) + 1e4 * eta,
            "slope_stderr": 1e-4,
            "n_points": 12,
            "method": method,
        }
        for model, eta in ETA.items()
        for n in (20, 21)  # N = 22 has no SSW fit
        for method in ("residual", "peak")
    ]
    return pd.DataFrame(rows)


def test_table_joins_c_and_ssw_per_model_and_chain():
    table = sweep_table(delay_fits(), ssw_fits(), ETA, "fit_full")
    assert tuple(table.columns) == SWEEP_COLUMNS
    # Simulation rows of one chain each, main estimator only, sorted by eta then N.
    assert list(table["model"]) == ["elastic"] * 3 + ["viscoelastic"] * 3
    assert list(table["N"]) == [20, 21, 22] * 2
    assert list(table["parity"]) == ["even", "odd", "even"] * 2
    expected_c = [38.0 + 0.1 * n for n in (20, 21, 22)] + [41.0 + 0.1 * n for n in (20, 21, 22)]
    np.testing.assert_allclose(table["C_us_N16"], expected_c)
    np.testing.assert_allclose(table["eta_s"], [0.0] * 3 + [0.58e-6] * 3)
    # The residual SSW method is taken; a chain without an SSW fit keeps its C.
    ssw = ssw_fits()
    residual = ssw[(ssw["method"] == "residual") & (ssw["model"] == "viscoelastic")]
    assert table.loc[3, "ssw_slope"] == residual[residual["N"] == 20]["slope"].iloc[0]
    assert math.isnan(table.loc[2, "ssw_slope"])


def test_figure_draws_the_table_values():
    table = sweep_table(delay_fits(), ssw_fits(), ETA, "fit_full")
    fig = fig_c_vs_N(table)
    ax = fig.axes[0]
    labels = ax.get_legend_handles_labels()[1]
    assert any("elastic (η = 0 µs), even N" == label for label in labels)
    assert any("viscoelastic (η = 0.58 µs), odd N" == label for label in labels)
    # Every C of the table is a plotted point (marker lines), nothing else besides the
    # paper's reference line.
    plotted = sorted(
        float(y) for line in ax.lines if line.get_marker() in ("o", "D") for y in line.get_ydata()
    )
    np.testing.assert_allclose(plotted, sorted(table["C_us_N16"]))
