"""The Snakemake pipeline end to end on a tiny config (tests/configs/tiny.yaml) in a
temporary directory: every contract file appears with its columns, a second run has
nothing to do, editing a library file reruns exactly what depends on it, and the
workflow is lint- and format-clean.

The run uses a copy of the library (``PYTHONPATH``) so that the test can touch its
source files without touching the checkout's.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "configs" / "tiny.yaml"
SNAKEMAKE = [sys.executable, "-m", "snakemake"]

pytestmark = pytest.mark.workflow

#: Columns each contract table must have (results contract + docs/interfaces.md).
TABLE_COLUMNS = {
    "pulses": [
        "source", "model", "N", "shot", "kind", "amplitude", "sensor", "bead", "role",
        "wave", "estimator", "F_m_N", "T_s", "tau_s", "ok", "reason",
    ],
    "delays": [
        "source", "model", "N", "shot", "amplitude", "wave", "estimator", "F_m_N",
        "delay_us", "tof_crossed_us", "tof_reference_us", "ok", "reason",
    ],
    "delay_fits": [
        "source", "model", "N", "estimator", "C_us_N16", "C_stderr_us_N16", "exponent",
        "exponent_stderr", "n_points",
    ],
    "ssw": ["source", "model", "N", "shot", "amplitude", "sensor", "F_m_N", "ssw_N"],
    "ssw_fits": ["source", "model", "N", "slope", "slope_stderr", "n_points"],
}  # fmt: skip

FIGURES = [
    "fig1_setup",
    "fig3_simulation_traces",
    "fig4_delay_vs_force",
    "fig5_ssw_vs_force",
    "fig_parity_ssw_vs_N",
]


def run(args, work: Path, env: dict, timeout=600) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SNAKEMAKE, "--snakefile", str(ROOT / "Snakefile"), "--directory", str(work), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )


def planned_jobs(work: Path, env: dict) -> dict[str, int]:
    """Rule -> number of jobs a dry run would execute."""
    result = run(["-n", "--cores", "2", "--configfile", str(TINY)], work, env)
    assert result.returncode == 0, result.stderr[-3000:]
    text = result.stdout + result.stderr
    if "Nothing to be done" in text:
        return {}
    table = text.split("Job stats:", 1)[1].split("total", 1)[0]
    return {m[1]: int(m[2]) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", table, re.M)}


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """The tiny run, done once: (work directory, results directory, env)."""
    base = tmp_path_factory.mktemp("workflow")
    work = base / "work"
    work.mkdir()
    shutil.copy(ROOT / "config.yaml", work / "config.yaml")
    library = base / "lib" / "chain"
    source = ROOT / "src" / "chain"
    # copy2 keeps mtimes, so numba's cache of the integrator stays valid in the copy.
    shutil.copytree(source, library, copy_function=shutil.copy2)
    env = {**os.environ, "PYTHONPATH": str(base / "lib")}
    result = run(["--cores", "2", "--configfile", str(TINY)], work, env)
    assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]
    return work, work / "results" / "tiny", env, library


def test_contract_files_and_columns(tiny):
    _, out, _, _ = tiny
    for name, columns in TABLE_COLUMNS.items():
        table = pd.read_csv(out / "tables" / f"{name}.csv")
        missing = [c for c in columns if c not in table.columns]
        assert not missing, f"{name}.csv lacks {missing}"
        assert len(table) > 0, f"{name}.csv is empty"
        assert set(table["source"]) == {"simulation"}
        assert set(table["model"]) == {"elastic", "viscoelastic"}
    for name in FIGURES:
        assert (out / "figures" / f"{name}.pdf").read_bytes().startswith(b"%PDF"), name
        assert (out / "figures" / f"{name}.png").read_bytes().startswith(b"\x89PNG"), name
    assert not (out / "figures" / "fig2_experiment_traces.png").exists()


def test_fits_cover_every_model_and_chain(tiny):
    _, out, _, _ = tiny
    fits = pd.read_csv(out / "tables" / "delay_fits.csv")
    keys = set(zip(fits["model"], fits["N"].astype(str), fits["estimator"]))
    for model in ("elastic", "viscoelastic"):
        for n in ("16", "17", "pooled"):
            for estimator in ("fit_full", "peak", "fit_rise"):
                assert (model, n, estimator) in keys
    ok = fits[fits["estimator"] == "fit_full"]
    assert ok["C_us_N16"].between(20, 80).all(), ok
    ssw_fits = pd.read_csv(out / "tables" / "ssw_fits.csv")
    assert len(ssw_fits) == 4


def test_simulation_outputs_logs_and_benchmarks(tiny):
    _, out, _, _ = tiny
    for model in ("elastic", "viscoelastic"):
        for n in (16, 17):
            traces = pd.read_csv(out / "simulation" / f"{model}_N{n}_traces.csv", nrows=5)
            assert list(traces.columns[:9]) == [
                "source", "model", "N", "shot", "kind", "amplitude",
                "v0_left_m_s", "v0_right_m_s", "t_s",
            ]  # fmt: skip
            runs = pd.read_csv(out / "simulation" / f"{model}_N{n}_runs.csv")
            assert len(runs) == 2 * 4  # collision + reference per speed
            assert (runs["energy_drift"] < 1e-6).all()
            assert (out / "benchmarks" / "simulate" / f"{model}_N{n}.tsv").exists()
            log = (out / "logs" / "simulate" / f"{model}_N{n}.log").read_text()
            assert "energy drift" in log
    assert (out / "logs" / "summary.log").exists()


def test_summary(tiny):
    _, out, _, _ = tiny
    summary = json.loads((out / "summary.json").read_text())
    assert summary["run_name"] == "tiny"
    assert set(summary["constants"]) >= {
        "kappa_N_m1_5",
        "bead_mass_kg",
        "C_bal_paper_us_N16",
        "C_bal_exact_us_N16",
    }
    assert summary["paper"] == {
        "C_exp_us_N16": 45.9,
        "C_exp_err_us_N16": 0.5,
        "C_bal_us_N16": 49.74,
    }
    assert 0 < summary["max_energy_drift"] < 1e-8
    assert len(summary["delay_fits"]) == 2 * 3 * 3
    assert len(summary["ssw_fits"]) == 4
    assert "| quantity | paper | this run | note |" in (out / "summary.md").read_text()


def test_second_run_has_nothing_to_do(tiny):
    work, _, env, _ = tiny
    assert planned_jobs(work, env) == {}


@pytest.mark.parametrize(
    ("module", "expected", "untouched"),
    [
        ("figures", set(FIGURES) | {"all"}, {"simulate", "pulses", "summary"}),
        ("ssw", {"ssw", "ssw_fits", "fig3_simulation_traces", "fig5_ssw_vs_force", "summary"},
         {"simulate", "pulses", "delays"}),
        ("model", {"simulate", "pulses", "delays", "ssw", "summary"}, set()),
    ],
)  # fmt: skip
def test_editing_the_library_reruns_what_depends_on_it(tiny, module, expected, untouched):
    work, _, env, library = tiny
    path = library / f"{module}.py"
    original, stat = path.read_bytes(), path.stat()
    try:
        # An edit, not a touch: Snakemake reruns only when the content changed.
        path.write_bytes(original + b"\n# an edit\n")
        jobs = planned_jobs(work, env)
    finally:
        path.write_bytes(original)
        os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    assert expected <= set(jobs), jobs
    assert not untouched & set(jobs), jobs
    if module == "model":
        assert jobs["simulate"] == 4


def test_lint_clean():
    result = subprocess.run(
        [*SNAKEMAKE, "--lint"], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    output = result.stdout + result.stderr
    assert "Congratulations, your workflow is in a good condition!" in output, output[-3000:]


def test_snakefmt_clean():
    snakefmt = shutil.which("snakefmt")
    if snakefmt is None:
        pytest.skip("snakefmt is not installed")
    result = subprocess.run(
        [snakefmt, "--check", "Snakefile", "workflow"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
