"""The sweep table (chain.studies.sweep) and its C(N) figure (chain.report.figures.fig_c_vs_N)."""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from chain.report.figures.fig_c_vs_N import fig_c_vs_N
from chain.studies.sweep import SWEEP_COLUMNS, sweep_table

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


# ---- the workflow wiring, by dry runs (no job runs) -------------------------------------

ROOT = Path(__file__).resolve().parents[1]


def dry_run(*args: str) -> str:
    """Output of ``snakemake -n`` in the checkout, with the checkout's library."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")]),
    }
    done = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--nolock", "--forceall", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout + done.stderr


@pytest.mark.workflow
def test_sweep_overlay_asks_for_its_table_and_both_figures():
    out = dry_run("--cores", "2", "--configfile", "whatif/sweep.yaml")
    for job in ("sweep_table", "fig_c_vs_N", "fig_parity_ssw_vs_N"):
        assert re.search(rf"^{job}\s+1$", out, flags=re.M), job
    # N = 18..27, three eta: one simulate job per model and chain, even and odd N.
    assert re.search(r"^simulate\s+30$", out, flags=re.M)
    assert "results/sweep/tables/sweep.csv" in out


@pytest.mark.workflow
def test_slurm_profile_gives_jobs_their_resources():
    pytest.importorskip("snakemake_executor_plugin_slurm")
    out = dry_run("--workflow-profile", "profiles/slurm", "--cores", "8")
    simulate = out[out.index("rule simulate:") :].split("\n\n")[0]
    # The paper's chains are small: one thread each (chain.pipeline.plan.resources).
    assert re.search(r"mem_mb=\d+00,.*runtime=\d+.*cpus_per_task=1", simulate), simulate
    fig1 = out[out.index("rule fig1_setup:") :].split("\n\n")[0]
    assert re.search(r"mem_mb=1000,.*runtime=15.*cpus_per_task=1", fig1), fig1
    # Job groups are off by default: a group asks SLURM for the sum of its jobs' CPUs,
    # which a small partition never grants (the live test's node has 2).
    assert "Group job" not in out


@pytest.mark.workflow
def test_slurm_profile_job_groups_as_documented_opt_in():
    """The profile's commented groups, given on the command line, put simulation jobs
    in one SLURM job (one allocation, one queue wait for several chains)."""
    pytest.importorskip("snakemake_executor_plugin_slurm")
    profile = (ROOT / "profiles" / "slurm" / "config.yaml").read_text()
    assert "# groups:\n#   - simulate=simulations" in profile
    out = dry_run(
        "--workflow-profile", "profiles/slurm", "--cores", "8",
        "--groups", "simulate=simulations", "ssw_track=simulations",
        "--group-components", "simulations=2",
    )  # fmt: skip
    assert "Group job simulations" in out
