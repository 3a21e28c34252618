"""summary.json / summary.md (chain.report.numbers.summary, summary_md) from synthetic tables."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pandas as pd
import pytest

from chain.labels import SKIPPED_REASON
from chain.physics.theory import ballistic_constants as run_constants
from chain.report.numbers.paper import PAPER
from chain.report.numbers.summary import build_summary, summary_json, write_summary_json
from chain.report.printed import E_NOTATION
from chain.report.text.markdown import summary_markdown, write_summary_markdown

#: The paper's Eq. 6 value and our recomputation agree to the printed digits.
CBAL_PAPER_ABS_US = 0.02

#: Ratio exact / Eq. 6: 2^(-2/5) (reduced mass m/2 instead of m) x 2.9432/2.94.
EXACT_OVER_PAPER = 2.0**-0.4 * 2.9432 / 2.94


def delay_fits() -> pd.DataFrame:
    rows = []
    for model, c in (("elastic", 40.0), ("viscoelastic", 43.2)):
        for n in (25, 26, "pooled"):
            for estimator in ("fit_full", "peak"):
                rows.append(
                    {
                        "source": "simulation",
                        "model": model,
                        "N": n,
                        "estimator": estimator,
                        "C_us_N16": c + (0.5 if estimator == "peak" else 0.0),
                        "C_stderr_us_N16": 0.2,
                        "exponent": -1 / 6,
                        "exponent_stderr": 0.003,
                        "n_points": 24,
                        "prefactor_free_us": c,
                    }
                )
    rows.append(
        {**rows[0], "model": "rig", "source": "experiment", "N": "pooled", "C_us_N16": 46.0}
    )
    rows.append({**rows[0], "model": "rig", "source": "experiment", "N": 25, "C_us_N16": math.nan})
    return pd.DataFrame(rows)


def ssw_fits() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "source": "simulation",
            "model": ["elastic", "elastic"],
            "N": [25, 26],
            "slope": [0.019, 0.047],
            "slope_stderr": [2e-5, 3e-5],
            "slope_stat": [2e-5, 3e-5],
            "slope_sys": [0.0, 0.0],
            "n_points": [24, 24],
            "n_resolved": [0, 24],
            "method": "residual",
        }
    )


def runs() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "model": ["elastic", "elastic", "viscoelastic"],
            "N": [25, 26, 25],
            "energy_drift": [3e-10, 4e-10, 5e-6],
        }
    )


@pytest.fixture()
def summary() -> dict:
    return build_summary(
        run_name="paper",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=ssw_fits(),
        runs=runs(),
        conservative_models=["elastic"],
        experiment_label="virtual experiment (model)",
    )


def test_run_constants_match_eq6():
    constants = run_constants("steel_100C6", 0.013)
    assert abs(constants["C_bal_paper_us_N16"] - PAPER["C_bal_us_N16"]) < CBAL_PAPER_ABS_US
    ratio = constants["C_bal_exact_us_N16"] / constants["C_bal_paper_us_N16"]
    assert ratio == pytest.approx(EXACT_OVER_PAPER, rel=1e-4)
    assert constants["bead_mass_kg"] == pytest.approx(4 / 3 * math.pi * 0.013**3 * 7780)
    assert constants["kappa_N_m1_5"] > 0


def test_contract_keys(summary):
    for key in ("run_name", "constants", "paper", "max_energy_drift", "delay_fits", "ssw_fits"):
        assert key in summary
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
    assert len(summary["delay_fits"]) == len(delay_fits())
    assert len(summary["ssw_fits"]) == 2


def test_max_energy_drift_is_over_conservative_runs_only(summary):
    assert summary["max_energy_drift"] == pytest.approx(4e-10)
    assert summary["energy_drift_by_model"]["viscoelastic"] == pytest.approx(5e-6)
    none = build_summary(
        run_name="x",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=ssw_fits(),
        runs=runs(),
        conservative_models=[],
    )
    assert none["max_energy_drift"] is None


def test_json_is_sorted_fixed_and_nan_free(summary):
    text = summary_json(summary)
    assert text.endswith("\n")
    data = json.loads(text)
    assert list(data) == sorted(data)
    assert "NaN" not in text
    nan_row = [r for r in data["delay_fits"] if r["source"] == "experiment" and r["N"] == 25]
    assert nan_row[0]["C_us_N16"] is None
    pooled = [r["N"] for r in data["delay_fits"] if not isinstance(r["N"], int)]
    assert set(pooled) == {"pooled"}
    assert summary_json(json.loads(text)) == text, "writing twice gives the same bytes"


def test_json_floats_have_fixed_precision():
    table = ssw_fits()
    table.loc[0, "slope"] = 1 / 3
    data = build_summary(
        run_name="x",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=table,
    )
    assert data["ssw_fits"][0]["slope"] == 0.3333333333
    assert isinstance(data["ssw_fits"][0]["n_points"], int)


def test_markdown_table(summary):
    text = summary_markdown(summary)
    assert "| quantity | paper | this run | note |" in text
    assert "49.74" in text and "45.9 ± 0.5" in text
    assert "reduced mass m/2" in text  # why the exact C_bal differs from Eq. 6
    assert "C, simulation, elastic, all N pooled, fit_full" in text
    assert "C, simulation, viscoelastic, N = 26, peak" in text
    assert "exponent p" in text
    assert "SSW slope, simulation, elastic, N = 26" in text
    assert "2.47 × the N = 25 slope" in text
    assert "C(viscoelastic) / C(elastic)" in text and "1.080" in text
    assert "4.00 × 10⁻¹⁰" in text  # a power of ten, never e-notation
    assert "rig: 46.0" in text  # the experiment's own pooled C
    assert "C, virtual experiment (model), rig, all N pooled, fit_full" in text
    assert "nan" not in text.lower().replace("nan ", "")
    rows = [line for line in text.splitlines() if line.startswith("| ")]
    assert all(line.count(" | ") == 3 for line in rows)


def test_markdown_other_material():
    data = build_summary(
        run_name="brass",
        material="brass",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=ssw_fits(),
    )
    text = summary_markdown(data)
    assert "not the paper's beads" in text
    assert "— (the paper's beads are steel_100C6)" in text
    assert "vs paper's C_exp" not in text  # no comparison with measurements on steel
    assert "not the paper's beads, so not comparable" in text  # the C_exp row says so
    assert "n/a (no conservative model)" in text


def write_summary(summary, json_path, md_path):
    """The two pipeline steps: summary.json, then summary.md from it."""
    write_summary_json(summary, json_path)
    write_summary_markdown(json_path, md_path)


def test_write_summary(tmp_path, summary):
    json_path, md_path = tmp_path / "out" / "summary.json", tmp_path / "out" / "summary.md"
    write_summary(summary, json_path, md_path)
    first = json_path.read_bytes(), md_path.read_bytes()
    write_summary(summary, json_path, md_path)
    assert (json_path.read_bytes(), md_path.read_bytes()) == first
    # The Markdown read back from the JSON is the Markdown of the summary itself.
    assert first[1].decode() == summary_markdown(json.loads(first[0]))
    assert sorted(p.name for p in json_path.parent.iterdir()) == ["summary.json", "summary.md"]
    assert json.loads(first[0])["run_name"] == "paper"
    assert np.isclose(json.loads(first[0])["max_energy_drift"], 4e-10)


# ---- guard rails: flagged rows, selection counts -------------------------------------


def delays_with_flags() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "source": ["simulation"] * 3 + ["experiment"] * 4,
            "model": ["elastic"] * 3 + ["rig"] * 4,
            "N": 25,
            "F_m_N": [10.0, 20.0, 30.0, 10.0, math.nan, 30.0, 40.0],
            "delay_us": [-20.0, -18.0, -17.0, math.nan, math.nan, -17.0, -16.0],
            "ok": [True, True, True, False, False, True, True],
        }
    )


def test_usable_rows_drops_flagged_and_nan_and_logs_the_count(caplog):
    from chain.analysis.rows import usable_rows

    table = delays_with_flags()
    table.loc[6, "delay_us"] = math.nan  # ok, but NaN: must not pass quietly
    with caplog.at_level("INFO", logger="chain.analysis.rows"):
        kept = usable_rows(table, ["F_m_N", "delay_us"], "delay rows")
    assert list(kept.index) == [0, 1, 2, 5]
    assert "delay rows: 3 of 7 left out (2 flagged ok = False, 1 ok but NaN/inf" in caplog.text
    text = table.assign(ok=table["ok"].map({True: "True", False: "False"}))
    assert list(usable_rows(text, ["F_m_N"]).index) == [0, 1, 2, 5, 6]
    positive = usable_rows(table, ["delay_us"], positive=True)
    assert positive.empty


def test_flag_and_selection_counts_in_summary():
    selection = pd.DataFrame(
        {
            "source": "experiment",
            "model": "rig",
            "N": [25, 25, 25, 26, 26],
            "shot": [0, 1, 2, 0, 1],
            "kind": ["collision", "collision", "reference", "collision", "reference"],
            "kept": [True, False, True, True, True],
        }
    )
    data = build_summary(
        run_name="x",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=ssw_fits(),
        delays=delays_with_flags(),
        selection=selection,
        tolerance=0.05,
        experiment_label="measured (rig)",
    )
    assert data["flagged"]["delays"] == {
        "experiment": {"rows": 4, "flagged": 2, "nan": 0},
        "simulation": {"rows": 3, "flagged": 0, "nan": 0},
    }
    assert data["flagged"]["pulses"] == {}
    assert data["selection"] == [
        {"model": "rig", "N": 25, "kind": "collision", "kept": 1, "rejected": 1},
        {"model": "rig", "N": 25, "kind": "reference", "kept": 1, "rejected": 0},
        {"model": "rig", "N": 26, "kind": "collision", "kept": 1, "rejected": 0},
        {"model": "rig", "N": 26, "kind": "reference", "kept": 1, "rejected": 0},
    ]
    assert data["experiment_tolerance"] == 0.05
    text = summary_markdown(data)
    assert (
        "| acceptance protocol, measured (rig) | collisions kept if the incident amplitudes "
        "differ by ≤ 5 % (Sec. IV); no counts printed | N = 25: 1 of 2 collisions kept, 1 of 1 "
        "references kept; N = 26: 1 of 1 collisions kept, 1 of 1 references kept |"
    ) in text
    assert "delays: 0 of 3 (simulation), 2 of 4 (measured (rig))" in text
    # The label names the series: no "rig" twice.
    assert "C, measured (rig), all N pooled, fit_full" in text
    assert "| 45.9 ± 0.5 | measured (rig): 46.00 ± 0.20 |" in text  # beside the paper's C_exp
    assert json.loads(summary_json(data))["selection"][0]["kept"] == 1


def test_skipped_shots_are_listed_in_the_summary():
    """A shot skipped for a dead channel (experiment.bad_channels: skip) is a rejected
    selection row with the channel as the reason; the summary lists it."""
    reason = f"{SKIPPED_REASON}: data/lab/shot_0003.csv: column bead17_V: dead channel"
    selection = pd.DataFrame(
        {
            "source": "experiment",
            "model": "rig",
            "N": 25,
            "shot": [0, 1],
            "kind": "collision",
            "kept": [True, False],
            "reason": ["kept: amplitude mismatch 1.0% <= 5%", reason],
        }
    )
    data = build_summary(
        run_name="x",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=ssw_fits(),
        selection=selection,
        tolerance=0.05,
        experiment_label="measured (rig)",
    )
    assert data["skipped_shots"] == [{"model": "rig", "N": 25, "shot": 1, "reason": reason}]
    text = summary_markdown(data)
    assert (
        "| shots skipped for a dead or saturated channel | — | 1: rig N = 25 shot 1: "
        "data/lab/shot_0003.csv: column bead17_V: dead channel |"
    ) in text


def test_no_experiment_no_selection_rows(summary):
    text = summary_markdown(summary)
    assert "acceptance protocol" not in text
    assert summary["selection"] == [] and summary["experiment_tolerance"] is None


def test_ssw_keys_and_rows():
    # One resolved shot of two at S2 of N = 26, none at N = 25 (measured there, upper
    # limits); the track separates for N = 26 only; long chains give the far field.
    ssw = pd.DataFrame(
        {
            "source": "simulation",
            "model": "elastic",
            "N": [25, 25, 26, 26],
            "sensor": "S2",
            "method": "residual",
            "ok": [True, True, True, False],
            "reason": ["", "", "", "x"],
            "F_m_N": 100.0,
            "ssw_N": [0.5, 0.6, 2.0, math.nan],
            "resolved": [False, False, True, False],
            "upper_limit": [True, True, False, False],
        }
    )
    fits = ssw_fits().assign(slope=[math.nan, 0.02], n_points=[0, 1])
    speed = pd.DataFrame(
        {
            "source": "simulation",
            "model": "elastic",
            "N": [25, 26, 120, 121],
            "wave": "LSTW",
            "ratio": [math.nan, 1.02, 1.018, 1.028],
            "first_separated_contact": pd.array([pd.NA, 17, 64, 66], dtype="Int64"),
            "distance_beads": [math.nan, 4.0, 4.0, 5.5],
            "n_shots_separated": [0, 12, 12, 12],
            "n_shots": [12, 12, 12, 12],
            "ssw_over_Fm": [math.nan, math.nan, 0.03, 0.0085],
            "ssw_over_Fm_err": [math.nan, math.nan, 3e-4, 1e-4],
        }
    )
    summary = build_summary(
        run_name="paper",
        material="steel_100C6",
        radius_m=0.013,
        delay_fits=delay_fits(),
        ssw_fits=fits,
        ssw=ssw,
        ssw_speed=speed,
    )
    resolved = {row["N"]: row for row in summary["ssw_resolved"]}
    assert resolved[25] == {
        "source": "simulation",
        "model": "elastic",
        "N": 25,
        "sensor": "S2",
        "resolved": False,
        "n_resolved": 0,
        "n_total": 2,
    }
    assert resolved[26]["resolved"] and resolved[26]["n_resolved"] == 1
    separation = {row["N"]: row for row in summary["ssw_separation"]}
    assert separation[25]["first_separated_contact"] is None
    assert separation[26]["first_separated_contact"] == 17
    assert separation[26]["distance_beads"] == 4.0 and separation[26]["speed_ratio"] == 1.02
    assert summary["ssw_parity_ratio"] == [
        {"source": "simulation", "model": "elastic", "ratio": None, "ratio_err": None}
    ]
    (far,) = summary["ssw_far_field"]
    assert (far["even_N"], far["odd_N"]) == (120, 121)
    assert far["ratio"] == pytest.approx(0.03 / 0.0085)
    # Relative errors in quadrature: 1 % and 1.18 %.
    assert far["ratio_err"] / far["ratio"] == pytest.approx(math.hypot(0.01, 1 / 85))
    json.loads(summary_json(summary))  # NaN-free
    text = summary_markdown(summary)
    assert "| SSW resolved at S2, simulation, elastic, N = 25 | — | no (0 of 2 shots)" in text
    assert (
        "| SSW resolved at S2, simulation, elastic, N = 26 | yes (Fig. 2 and 3, C and D) |" in text
    )
    assert "contact 17 (4 beads from the collision point)" in text
    assert "never within the chain" in text
    assert (
        "| SSW speed / Eq. 5 for its amplitude, simulation, elastic, N = 26 | — | 1.020 |" in text
    )
    assert "SSW slope ratio, simulation, elastic, N = 26 : N = 25 | > 1" in text
    assert "SSW far field, even : odd, simulation, elastic, N = 120 : 121 | > 1" in text


def test_markdown_has_no_raw_e_notation(summary):
    """Very small or large numbers are written with a power of ten,
    in the rendered summary.md as in the article (chain.report.printed.power_of_ten)."""
    data = copy.deepcopy(summary)
    data["max_energy_drift"] = 5.48e-10
    data["constants"]["kappa_N_m1_5"] = 1.199e10
    data["ssw_mechanisms"] = {
        "verdict": "Of the candidates, gaps between beads (gap_mean_m=1e-07) comes closest.",
        "rows": [],
        "lammps_check": [{"rel_diff_C": 3.5e-06, "max_trace_diff_over_Fm": 3.2e-05}],
    }
    data["attenuation"] = [
        {"model": "elastic", "N": 25, "F_S1_low_N": 9.99, "ratio_low": 1.0,
         "F_S1_high_N": 1030.0, "ratio_high": 1.0},
    ]  # fmt: skip
    text = summary_markdown(data)
    assert not E_NOTATION.findall(text), E_NOTATION.findall(text)
    assert "5.48 × 10⁻¹⁰" in text and "1 × 10⁻⁷" in text and "3.5 × 10⁻⁶" in text
    assert "1.199 × 10¹⁰" in text and "1.03 × 10³ N" in text


def test_e_notation_pattern_finds_numbers_not_hashes():
    found = E_NOTATION.findall("drift 5.5e-10, 1e+03 N, -2E5; commit 7ef8d179e4b2, T1e5")
    assert found == ["5.5e-10", "1e+03", "-2E5"]


def test_studies_switched_off_are_said_not_run(summary):
    """summary.md names each study the config switched off (``studies_not_run``), where
    its rows would be; a run that made them all has no such line."""
    assert "not run in this run" not in summary_markdown(summary)
    text = summary_markdown({**summary, "studies_not_run": ["ablation", "mechanisms"]})
    assert "| not run in this run (config studies.ablation: false) |" in text
    assert "The mechanism study: not run in this run (config studies.mechanisms: false)." in text
    assert "studies.c_sensitivity" not in text
