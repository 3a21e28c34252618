"""C against our choices (chain.studies.c_sensitivity), its summary entries
(chain.report.numbers.spread) and its figure (chain.report.figures.fig_c_sensitivity)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from snakemake.utils import validate

from chain.apparatus.shots import simulate_shots
from chain.physics.builders import uniform_chain
from chain.pipeline.plan.run_plan import launch_speeds
from chain.report.figures.fig_c_sensitivity import fig_c_sensitivity
from chain.report.numbers.spread import ablation_summary, c_spread_summary
from chain.report.text.markdown_studies import spread_markdown_rows
from chain.studies.c_sensitivity import (
    c_sensitivity_table,
    sensitivity_plan,
    shifted_pairs,
)

ROOT = Path(__file__).resolve().parents[1]


def test_shifted_pairs_stay_inside_the_chain():
    chains = {25: (9, 17), 26: (10, 17)}
    assert shifted_pairs(chains, 2) == {25: (11, 15), 26: (12, 15)}
    assert shifted_pairs(chains, -4) == {25: (5, 21), 26: (6, 21)}
    assert shifted_pairs(chains, 4) is None  # (13, 13) is no pair
    assert shifted_pairs(chains, -9) is None  # bead 0


def test_plan_of_the_paper_config():
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    validate(config, str(ROOT / "workflow" / "schemas" / "config.schema.yaml"))
    plan = sensitivity_plan(config, launch_speeds(config["launch"]))
    assert plan["eta_s"] == pytest.approx([0.0, 0.58e-6, 1.16e-6])
    assert plan["shifts"] == [2, -2, -4]
    assert len(plan["speeds_m_s"]) == 12


@pytest.fixture(scope="module")
def small_study():
    """(traces, plan): a 16-bead chain, four launch speeds, eta 0 / 0.58 / 1.16 us."""
    chains = {16: [6, 11]}
    plan = {
        "chains": chains,
        "eta_s": [0.0, 0.58e-6, 1.16e-6],
        "estimators": ["fit_full", "peak"],
        "main_estimator": "fit_full",
        "shifts": [-2],
        "speeds_m_s": [0.05, 0.1, 0.2, 0.4],
    }
    traces = {}
    for eta in plan["eta_s"]:
        model = uniform_chain(16, eta=eta)
        table, _ = simulate_shots(
            model, plan["speeds_m_s"], [4, 6, 11, 13], model_name="m", duration=1.4e-3
        )
        traces[eta] = {16: table}
    return traces, plan


@pytest.fixture(scope="module")
def small_table(small_study):
    return c_sensitivity_table(*small_study)


def test_recorded_readings_give_the_shots_the_study_would_simulate_bit_for_bit(tmp_path):
    """A simulate job records every bead's felt force (its readings); the study reads its
    shifted sensors there instead of integrating the same launches again: the trace
    table is the one simulated for those beads alone, bit for bit (recording every
    contact does not change the integration)."""
    from chain.apparatus.readings import readings_table, save_readings
    from chain.apparatus.shots import simulate_launches

    model, speeds, beads = uniform_chain(16, eta=0.58e-6), [0.05, 0.2], [4, 6, 11, 13]
    alone, _ = simulate_shots(model, speeds, beads, model_name="m", duration=1.4e-3)
    save_readings(simulate_launches(model, speeds, duration=1.4e-3), tmp_path / "r.npz")
    read = readings_table(tmp_path / "r.npz", beads, model_name="m")
    pd.testing.assert_frame_equal(read, alone, check_exact=True)


def test_elastic_row_has_the_hertz_exponent(small_table):
    """Without dissipation the scaling symmetry gives |Delta| ~ F_m^(-1/6) exactly."""
    row = small_table[(small_table["choice"] == "eta_us") & (small_table["value"] == "0")]
    row = row[row["N"].astype(str) == "16"].iloc[0]
    assert row["exponent"] == pytest.approx(-1 / 6, abs=2e-3)
    assert row["n_points"] == 8  # 4 amplitudes x 2 waves


def test_dissipation_raises_c_and_headline_rows_agree(small_table):
    eta = small_table[(small_table["choice"] == "eta_us") & (small_table["N"].astype(str) == "16")]
    assert np.all(np.diff(eta["C"].to_numpy()) > 0)  # C grows with eta
    head = small_table[small_table["headline"]]
    assert set(head["choice"]) == {"estimator", "eta_us", "sensors", "amplitudes"}
    assert head["C"].nunique() <= 2  # the same fit (per N, pooled) repeated


def test_spread_summary_and_figure(small_table):
    spread = c_spread_summary({"table": small_table}, {})
    assert spread["min_us_N16"] <= spread["headline_C_us_N16"] <= spread["max_us_N16"]
    assert "fit_full" in spread["headline_choice"]
    rows = spread_markdown_rows({"c_spread": spread})
    assert len(rows) == 1 and "c_sensitivity.csv" in rows[0][3]
    fig = fig_c_sensitivity(small_table)
    assert fig.axes[0].get_ylabel().startswith("C")


def test_ablation_verdict_names_the_numbers():
    fits = pd.DataFrame(
        {
            "source": ["experiment", "simulation"],
            "model": ["virtual", "viscoelastic"],
            "N": ["pooled", "pooled"],
            "estimator": "fit_full",
            "exponent": [-0.214, -0.152],
            "exponent_stderr": [0.011, 0.003],
        }
    )
    ablation = pd.DataFrame(
        {
            "variant": ["no_reference_mismatch", "no_imperfections"],
            "N": "pooled",
            "exponent": [-0.169, -0.154],
            "exponent_stderr": [0.010, 0.005],
        }
    )
    # Printed with the minus sign U+2212 (chain.report.printed); compared as ASCII.
    run = {"delay_fits": fits, "estimator": "fit_full"}
    verdict = ablation_summary({"table": ablation}, run)["verdict"].replace("\u2212", "-")
    for number in ("-0.214", "-0.169", "-0.154", "viscoelastic -0.152"):
        assert number in verdict
    missing = ablation_summary(
        {"table": ablation.iloc[:1]}, {"delay_fits": fits, "estimator": "fit_full"}
    )["verdict"]
    assert missing.startswith("not determined")
