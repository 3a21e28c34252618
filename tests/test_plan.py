"""The run plan (chain.pipeline.plan.run_plan.RunPlan): each fact of a run derived once from the
checked config, and a simulate job's inputs as a cache key."""

from __future__ import annotations

import copy
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from snakemake.utils import validate

from chain.pipeline.config.check import check_config
from chain.pipeline.plan import figures
from chain.pipeline.plan.jobs import JOB_KEYS, chain_of
from chain.pipeline.plan.run_plan import RunPlan

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


def checked(config: dict) -> dict:
    """A config as the Snakefile has it: validated (defaults filled in), checked."""
    config = copy.deepcopy(config)
    validate(config, str(SCHEMA))
    check_config(config)
    return config


@pytest.fixture(scope="module")
def paper() -> dict:
    return checked(yaml.safe_load((ROOT / "config.yaml").read_text()))


@pytest.fixture(scope="module")
def plan(paper) -> RunPlan:
    return RunPlan(paper, root=str(ROOT))


def test_job_inputs_change_with_the_physics_only(paper, plan):
    job = plan.simulate_job("viscoelastic", 26)
    assert tuple(job) == JOB_KEYS
    assert json.loads(json.dumps(job)) == job  # a cache can hash its JSON text
    # An analysis or figure key does not change what the simulation computes...
    analysis = copy.deepcopy(paper)
    analysis["analysis"]["main_estimator"] = "peak"
    analysis["figures"]["representative_force_N"] = 100.0
    assert RunPlan(analysis).simulate_job("viscoelastic", 26) == job
    # ...a contact law does, and only for the model it belongs to.
    eta = copy.deepcopy(paper)
    eta["models"][1]["eta_s"] = 1.0e-6
    assert RunPlan(eta).simulate_job("viscoelastic", 26) != job
    assert RunPlan(eta).simulate_job("elastic", 26) == plan.simulate_job("elastic", 26)


def test_launch_speeds_are_the_configured_geometric_series(plan):
    speeds = np.array(plan.speeds)
    assert len(speeds) == 12 and speeds[0] == 0.021 and speeds[-1] == 1.0
    assert np.diff(np.log(speeds)) == pytest.approx(np.log(1.0 / 0.021) / 11, rel=1e-9)
    # Every simulation of the run, the C-sensitivity study's too, launches at them.
    assert plan.simulate_job("elastic", 25)["speeds_m_s"] == list(plan.speeds)
    assert plan.c_sensitivity.choices["speeds_m_s"] == list(plan.speeds)
    assert all(job["speeds_m_s"] == list(plan.speeds) for job in plan.c_sensitivity.jobs())


def test_the_chain_follows_the_readout(paper):
    felt = RunPlan(paper).chain("viscoelastic", 25)
    assert felt.n_particles == 25 and not felt.is_conservative
    sensor = copy.deepcopy(paper)
    sensor["simulation"]["readout"] = "sensor"
    split = RunPlan(checked(sensor)).chain("viscoelastic", 25)
    # Each of the two sensor beads is split in two halves joined by the sensor spring.
    assert split.n_particles == 27
    assert chain_of(RunPlan(checked(sensor)).simulate_job("elastic", 25)).is_conservative


def test_conservative_models_and_the_spacetime_model(paper, plan):
    assert plan.conservative == ("elastic",)
    assert plan.simulation.spacetime_model == "elastic"
    dissipative = copy.deepcopy(paper)
    dissipative["models"] = [{"name": "viscoelastic", "eta_s": 0.58e-6}]
    dissipative["figures"]["traces_model"] = "viscoelastic"
    other = RunPlan(dissipative)
    assert other.conservative == () and other.simulation.spacetime_model == "viscoelastic"


def test_durations_and_long_chains(paper, plan):
    assert plan.duration(25) == paper["simulation"]["duration_s"]
    # A long chain runs in proportion to N (longest configured chain: 26 beads).
    assert plan.duration(120) == pytest.approx(2.6e-3 * 120 / 26)
    assert plan.tracked_chains == (25, 26, 120, 121)
    long = plan.simulate_job("elastic", 121)
    assert long["sensors"] == [] and long["duration_s"] == plan.duration(121)
    with pytest.raises(KeyError, match="N = 30"):
        plan.simulate_job("elastic", 30)


def test_the_virtual_experiment_takes_the_config_names(paper, plan):
    settings = plan.experiment.model(26)
    virtual = paper["experiment"]["virtual"]
    for key, value in virtual.items():
        got = getattr(settings, key)
        assert got == (tuple(value) if isinstance(value, list) else value), key
    assert settings.seed == paper["seed"] + 26 and settings.sensor_beads == (10, 17)
    assert settings.striker_radius == paper["setup"]["striker_radius_m"]
    settings = plan.experiment.settings(26)
    assert json.loads(json.dumps(settings)) == settings


def test_targets_follow_the_experiment_and_the_studies(paper, plan):
    assert plan.experiment.label == "virtual experiment (model)"
    assert f"{plan.tables}/ablation_exponent.csv" in plan.targets()
    assert "fig2_experiment_traces" in plan.figures.names()
    none = copy.deepcopy(paper)
    none["experiment"]["source"] = "none"
    none["studies"]["mechanisms"] = False
    bare = RunPlan(none)
    assert bare.experiment.chains == () and bare.experiment.label == "experiment"
    assert "fig2_experiment_traces" not in bare.figures.names()
    assert bare.ablation.targets() == []
    assert bare.mechanisms.candidates(full=True) == {} and not bare.mechanisms.lammps
    assert not any("ssw_mechanisms" in path for path in bare.targets())


def figure(name: str) -> list[str]:
    return [f"figures/{name}.pdf", f"figures/{name}.png"]


# Each study's own files (tables/<name>.csv, figures/<name>.pdf|png).
STUDY_FILES = {
    "ablation": ["tables/ablation_exponent.csv"],
    "c_sensitivity": ["tables/c_sensitivity.csv", *figure("fig_c_sensitivity")],
    "mechanisms": ["tables/ssw_mechanisms.csv", *figure("fig_ssw_mechanisms")],
}


@pytest.mark.parametrize("study", sorted(STUDY_FILES))
def test_a_study_switched_off_leaves_exactly_its_files(paper, plan, study):
    config = copy.deepcopy(paper)
    config["studies"][study] = False
    off = RunPlan(config)
    own = {f"{plan.out}/{path}" for path in STUDY_FILES[study]}
    assert own <= set(plan.targets())
    if study == "mechanisms":
        own |= {path for path in plan.targets() if "lammps_check" in path}
        assert not off.mechanisms.lammps and off.mechanisms.candidates(full=False) == {}
    assert set(off.targets()) == set(plan.targets()) - own
    assert off.studies_not_run == [study] and plan.studies_not_run == []


def test_the_paper_run_makes_every_study_and_the_schema_defaults_to_all(paper):
    assert paper["studies"] == {"ablation": True, "c_sensitivity": True, "mechanisms": True}
    bare = copy.deepcopy(yaml.safe_load((ROOT / "config.yaml").read_text()))
    del bare["studies"]
    assert checked(bare)["studies"] == paper["studies"]


def test_variants_with_the_runs_settings_read_the_runs_virtual_experiment(plan):
    raw = [plan.experiment.raw_dataset(n) for n in plan.chains]
    assert raw == [f"{plan.out}/experiment/raw/N25", f"{plan.out}/experiment/raw/N26"]
    # The reference of the candidates and a tolerance-only variant are the run's own
    # shots; of as_configured's 8 seeds, the first is the run's.
    assert plan.ablation.datasets("mechanism_reference") == [raw]
    assert plan.ablation.datasets("no_selection") == [raw]
    assert plan.ablation.datasets("as_configured") == [raw] + [[]] * 7
    assert plan.ablation.tolerance("no_selection") is None
    # Any change to the shots (one seed, one switch) simulates anew.
    for name in ("no_reference_mismatch", "no_noise_adc", "kk_2us", "off_centre_5pct"):
        assert plan.ablation.datasets(name) == [[]], name


def test_only_a_virtual_run_shares_its_experiment(paper):
    config = copy.deepcopy(paper)
    config["experiment"]["source"] = "none"
    assert RunPlan(config).ablation.datasets("mechanism_reference") == [[]]


def test_identical_variants_are_twins_of_the_first(paper, plan):
    assert plan.ablation.twins == {"sensor_bead_off": "point_readout"}
    assert plan.ablation.settings("sensor_bead_off") == plan.ablation.settings("point_readout")
    # Another tolerance makes another analysis: no longer a twin.
    config = copy.deepcopy(paper)
    for variant in config["ablation"]["variants"]:
        if variant["name"] == "sensor_bead_off":
            variant["set"]["tolerance"] = 0.1
    assert RunPlan(config).ablation.twins == {}


def test_the_plan_is_frozen_and_keeps_its_own_config(paper):
    config = copy.deepcopy(paper)
    plan = RunPlan(config)
    config["launch"]["count"] = 3
    assert len(plan.speeds) == 12 and plan.config["launch"]["count"] == 12
    with pytest.raises(dataclasses.FrozenInstanceError):
        plan.speeds = ()


def test_a_figure_registered_once_is_a_target_a_report_entry_and_in_the_article(paper, monkeypatch):
    """One entry in the figure registry, and the run asks for the figure, makes a rule
    for it (its script by its name, the PNG for the HTML report), and the article embeds
    it; the workflow end to end: tests/test_workflow.py (report and article)."""
    entry = figures.Figure(
        "fig_ssw_speed", inputs=lambda p: {"speed": p.analysis.table("ssw_speed")}
    )
    monkeypatch.setattr(figures, "FIGURES", (*figures.FIGURES, entry))
    plan = RunPlan(paper)
    pdf, png = (f"{plan.figures_dir}/fig_ssw_speed.{ext}" for ext in ("pdf", "png"))
    assert {pdf, png} <= set(plan.targets())
    (step,) = [s for s in plan.steps if s.name == "fig_ssw_speed"]
    assert step.script_name == "fig_ssw_speed" and step.report == {
        "png": ("fig_ssw_speed.rst", "Figures")
    }
    job = plan.jobs.producer(png)
    assert job.outputs == {"pdf": pdf, "png": png}
    assert job.inputs["speed"] == f"{plan.tables}/ssw_speed.csv"
    assert job.log == f"{plan.out}/logs/figures/fig_ssw_speed.log"
    assert pdf in plan.jobs.producer(f"{plan.out}/article.pdf").inputs["figures"]
    assert plan.jobs.producer(png) in plan.jobs.needed(plan.targets())


def test_the_plan_knows_every_job_of_the_run_and_what_each_reads(plan):
    """The default run's jobs, each after the jobs it reads from; each wildcard held to
    the plan's values, so that Snakemake's rules make exactly these jobs."""
    jobs = plan.jobs.needed(plan.targets())
    seen = set()
    for job in jobs:
        for path in job.input_paths:
            producer = plan.jobs.producer(path)
            assert producer is None or id(producer) in seen, (job, path)
        seen.add(id(job))
    rules = {}
    for job in jobs:
        rules[job.rule] = rules.get(job.rule, 0) + 1
    assert rules["simulate"] == 4 and rules["ssw_track"] == 8 and rules["pulses"] == 1
    simulate = plan.jobs.steps["simulate"]
    assert simulate.constraints() == {"model": "elastic|viscoelastic", "N": "25|26"}
    assert set(plan.target_files(["ablation"])) == {f"{plan.tables}/ablation_exponent_all.csv"}
    assert plan.target_files([]) == plan.targets()
