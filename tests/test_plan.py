"""The run plan (chain.pipeline.plan): each fact of a run derived once from the checked
config, as the rule files read it: RunPlan (models, chains, speeds, durations, a
simulate job's inputs), SimulationPlan, ExperimentPlan, and the studies' parts
(AblationPlan, CSensitivityPlan, MechanismPlan). The plan knows no Snakemake; the
workflow end to end is tests/test_workflow.py.

A figure is its module (chain.report.figures), its script (workflow/scripts/<rule>.py)
and its rule (outputs pdf and png, the PNG in the HTML report) with ``publish_figure``
(the run folder and the article): :func:`test_a_figure_is_its_module_its_script_and_its_rule`.
"""

from __future__ import annotations

import ast
import copy
import json
import re
from pathlib import Path

import numpy as np
import pytest
import yaml
from snakemake.utils import validate

from chain.pipeline.config.check import check_config
from chain.pipeline.plan.ablation import AblationPlan
from chain.pipeline.plan.c_sensitivity import CSensitivityPlan
from chain.pipeline.plan.jobs import JOB_KEYS, chain_of
from chain.pipeline.plan.mechanisms import MechanismPlan
from chain.pipeline.plan.run_plan import RunPlan

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
RULES = ROOT / "workflow" / "rules"


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


def changed(paper: dict, **sections) -> dict:
    """``paper`` with ``sections`` (section -> {key: value}) changed, checked again."""
    config = copy.deepcopy(paper)
    for section, values in sections.items():
        config[section].update(values)
    return checked(config)


# ---- RunPlan -----------------------------------------------------------------------------


def test_job_inputs_change_with_the_physics_only(paper, plan):
    job = plan.simulate_job("viscoelastic", 26)
    assert tuple(job) == JOB_KEYS
    assert json.loads(json.dumps(job)) == job  # a recipe's key hashes its JSON text
    # An analysis or figure key does not change what the simulation computes...
    analysis = copy.deepcopy(paper)
    analysis["analysis"]["main_estimator"] = "peak"
    analysis["figures"]["representative_force_N"] = 100.0
    assert RunPlan(analysis).simulate_job("viscoelastic", 26) == job
    # ...nor does the run's name (a renamed run shares every simulation)...
    assert RunPlan({**paper, "run_name": "again"}).simulate_job("viscoelastic", 26) == job
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
    study = CSensitivityPlan(plan)
    assert study.choices["speeds_m_s"] == list(plan.speeds)
    assert all(job["speeds_m_s"] == list(plan.speeds) for job in study.jobs())


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
    assert plan.sensors(121) == () and plan.sensors(26) == (10, 17)
    with pytest.raises(KeyError, match="N = 30"):
        plan.simulate_job("elastic", 30)


def test_studies_switched_on_and_off(paper, plan):
    assert paper["studies"] == {"ablation": True, "c_sensitivity": True, "mechanisms": True}
    assert plan.studies_not_run == [] and all(map(plan.study, paper["studies"]))
    off = RunPlan(changed(paper, studies={"c_sensitivity": False, "ablation": False}))
    assert off.studies_not_run == ["ablation", "c_sensitivity"]
    assert not off.study("ablation") and off.study("mechanisms")
    bare = copy.deepcopy(yaml.safe_load((ROOT / "config.yaml").read_text()))
    del bare["studies"]
    assert checked(bare)["studies"] == paper["studies"]  # the schema's default: all


def test_the_plan_keeps_its_own_config(paper):
    config = copy.deepcopy(paper)
    plan = RunPlan(config)
    config["launch"]["count"] = 3
    config["models"].pop()
    assert len(plan.speeds) == 12 and plan.config["launch"]["count"] == 12
    assert list(plan.models) == ["elastic", "viscoelastic"]


def test_the_article_states_the_setup_and_the_summary_the_provenance(paper):
    provenance = {"commit": "abc", "config_hash": "123"}
    plan = RunPlan(paper, provenance=provenance)
    assert plan.provenance == provenance and plan.provenance is not provenance
    assert plan.article_setup["chains"] == paper["chains"]
    assert plan.article_setup["source"] == "virtual"
    assert plan.article_setup["tolerance"] == paper["experiment"]["tolerance"]
    assert plan.out == "results/paper" and plan.run_name == "paper"


# ---- SimulationPlan ------------------------------------------------------------------------


def test_the_simulation_plan_asks_what_a_job_is_worth(plan):
    simulation = plan.simulation
    assert simulation.field_chains == (25, 26, 120, 121)
    wildcards = {"model": "viscoelastic", "N": "26"}
    threads = simulation.threads(wildcards)
    assert isinstance(threads, int) and threads >= 1
    assert simulation.mem_mb(wildcards, threads) > 0 and simulation.runtime(wildcards, threads) > 0
    # A long chain is more work: never less memory or time.
    long = {"model": "viscoelastic", "N": "121"}
    assert simulation.mem_mb(long, threads) >= simulation.mem_mb(wildcards, threads)
    assert simulation.runtime(long, threads) >= simulation.runtime(wildcards, threads)


def test_the_spacetime_figure_shows_the_chains_of_fig3(paper):
    config = copy.deepcopy(paper)
    config["figures"]["traces_N"] = [26]
    plan = RunPlan(checked(config))
    assert plan.traces_n == (26,) and plan.simulation.field_chains == (26, 120, 121)


# ---- ExperimentPlan ------------------------------------------------------------------------


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


def test_the_experiment_plan_names_its_chains_and_files(plan):
    experiment = plan.experiment
    assert experiment.virtual and experiment.label == "virtual experiment (model)"
    assert [part.n_beads for part in experiment.chains] == [25, 26]
    assert experiment.virtual_n == [25, 26] and experiment.measured_files == []
    assert experiment.series == "virtual"
    assert experiment.trace_files == {
        "series0": "experiment/virtual_N25_traces.csv",
        "series1": "experiment/virtual_N26_traces.csv",
    }
    assert experiment.shown((26,)) == ["series1"] and experiment.shown() == ["series0", "series1"]
    loading = experiment.loading
    assert loading["bad_channels"] == "stop"
    assert loading["datasets"] == [
        {"folder": None, "name": "virtual", "N": 25},
        {"folder": None, "name": "virtual", "N": 26},
    ]
    experiment.check_datasets()  # nothing measured: nothing to check


def test_a_measured_dataset_is_read_and_named(paper):
    config = copy.deepcopy(paper)
    config["experiment"].update(source="measured", datasets=["tests/data/virtual_small"])
    config["chains"] = [{"N": 25, "sensors": [9, 17]}]
    plan = RunPlan(checked(config), root=str(ROOT))
    experiment = plan.experiment
    assert not experiment.virtual and experiment.virtual_n == []
    assert experiment.label == "virtual experiment (model): virtual_small"
    assert experiment.trace_files == {"series0": "experiment/virtual_small_N25_traces.csv"}
    files = experiment.measured_files
    assert any(f.endswith("metadata.yaml") for f in files)
    assert any(re.search(r"shot_\d+\.csv$", f) for f in files)
    assert experiment.loading["datasets"][0]["folder"] is not None


def test_no_experiment_has_no_chains_and_no_label_of_a_model(paper):
    bare = RunPlan(changed(paper, experiment={"source": "none"}))
    assert bare.experiment.chains == () and bare.experiment.label == "experiment"
    assert bare.experiment.trace_files == {} and bare.experiment.virtual_n == []


# ---- the studies' parts ------------------------------------------------------------------


def test_the_default_ablation_makes_the_default_run_variants_and_the_candidates(plan):
    ablation = AblationPlan(plan)
    assert ablation.names(full=False) == ["no_reference_mismatch", "no_imperfections"]
    assert ablation.names(full=True) == list(ablation.variants) and not ablation.full
    candidates = ablation.candidates(full=False)
    assert "mechanism_reference" in candidates and len(candidates) > 1
    # The one job makes the tables' variants and the mechanism study's candidates, in
    # config order; the candidates' SSW is fitted, the others' not.
    assert set(ablation.made) == set(ablation.names(full=False)) | set(candidates)
    assert ablation.made == [name for name in ablation.variants if name in ablation.made]
    job = ablation.job()
    assert list(job) == ablation.made
    assert {name for name, variant in job.items() if variant["ssw"]} == set(candidates)
    assert json.loads(json.dumps(job)) == job  # a param: plain values
    assert set(ablation.overrides) == set(ablation.variants)
    settings = ablation.settings("as_configured")
    assert len(settings) == 8 and all(len(replicate) == 2 for replicate in settings)


def test_variants_with_the_runs_settings_are_the_runs_virtual_experiment(plan):
    """A variant (or a replicate) whose settings are the run's virtual experiment's, for
    every chain, has the run's shots (the job reads them from its datasets)."""
    ablation = AblationPlan(plan)
    run = [plan.experiment.settings(n) for n in plan.chains]
    the_runs = {name: [s == run for s in ablation.settings(name)] for name in ablation.variants}
    # The candidates' reference and a tolerance-only variant are the run's own shots; of
    # as_configured's 8 seeds, the first is the run's.
    assert the_runs["mechanism_reference"] == [True] and the_runs["no_selection"] == [True]
    assert the_runs["as_configured"] == [True] + [False] * 7
    assert ablation.tolerance("no_selection") is None
    assert ablation.tolerance("as_configured") == plan.config["experiment"]["tolerance"]
    # Any change to the shots (one seed, one switch) simulates anew.
    for name in ("no_reference_mismatch", "no_noise_adc", "kk_2us", "off_centre_5pct"):
        assert the_runs[name] == [False], name
    # Variants that change nothing the shots depend on are the same settings.
    assert ablation.settings("sensor_bead_off") == ablation.settings("point_readout")


def test_only_a_virtual_run_makes_the_ablation(paper):
    ablation = AblationPlan(RunPlan(changed(paper, experiment={"source": "none"})))
    assert ablation.names(full=False) == [] and ablation.made == []
    assert ablation.candidates(full=True) == {}


def test_a_full_study_is_every_variant_and_setting(paper):
    plan = RunPlan(changed(paper, studies={"ablation": "full", "mechanisms": "full"}))
    ablation = AblationPlan(plan)
    mechanisms = MechanismPlan(plan, ablation)
    assert ablation.full and mechanisms.full and ablation.made == list(ablation.variants)
    assert len(mechanisms.candidates(full=True)) > len(mechanisms.candidates(full=False)) > 0


def test_the_c_sensitivity_study_reads_the_simulations_of_the_configured_eta(plan):
    study = CSensitivityPlan(plan)
    choices = study.choices
    assert choices["main_estimator"] == "fit_full" and choices["chains"] == {
        25: [9, 17],
        26: [10, 17],
    }
    jobs = study.jobs()
    assert [(job["eta_s"], job["N"]) for job in jobs] == [
        (eta, n) for eta in choices["eta_s"] for n in (25, 26)
    ]
    # Every sensor bead of every shifted pair is recorded.
    assert all({9, 17} <= set(job["sensors"]) for job in jobs if job["N"] == 25)
    assert study.job(2, 26) == jobs[-1]
    # A configured model's eta: its simulate job recorded the shots; another eta, the
    # study's own simulation.
    readings = study.readings()
    assert len(readings) == len(jobs)
    assert len({json.dumps(reading, sort_keys=True) for reading in readings}) == len(jobs)
    for job, (rule, output, wildcards) in zip(jobs, readings):
        model = study.recorded_by(job)
        if model is None:
            assert rule != "simulate", (rule, output, wildcards)
        else:
            assert plan.models[model] == job["eta_s"]
            expected = ("simulate", "readings", {"model": model, "N": job["N"]})
            assert (rule, output, wildcards) == expected
    assert {study.recorded_by(job) for job in jobs} == {"elastic", "viscoelastic", None}


def test_split_sensor_beads_are_never_read_from_the_felt_simulations(paper):
    sensor = copy.deepcopy(paper)
    sensor["simulation"]["readout"] = "sensor"
    study = CSensitivityPlan(RunPlan(checked(sensor)))
    assert [study.recorded_by(job) for job in study.jobs()] == [None] * len(study.jobs())


def test_the_mechanism_study_settings_and_candidates(paper, plan):
    mechanisms = MechanismPlan(plan, AblationPlan(plan))
    candidates = mechanisms.candidates(full=False)
    assert "mechanism_reference" in candidates and len(candidates) > 1
    assert set(mechanisms.candidates(full=True)) > set(candidates)
    params = mechanisms.table_params
    assert params["candidate_reference"] == "mechanism_reference"
    assert set(mechanisms.lammps_config) <= {"material", "radius_m", "chains", "models", "lammps"}
    if mechanisms.lammps:
        defaults = mechanisms.settings("lammps", full=False)
        assert defaults[0] == params["lammps_reference"] and len(defaults) == 4
        assert set(mechanisms.settings("lammps", full=True)) > set(defaults)
        assert mechanisms.settings("viscous", full=False) == ["visc10"]
        assert mechanisms.notes() == []
    else:
        assert mechanisms.settings("lammps", full=False) == []
        assert "LAMMPS is not importable" in mechanisms.notes()[0]
    assert mechanisms.table_made


def test_the_mechanism_study_switched_off_makes_nothing(paper):
    off = RunPlan(changed(paper, studies={"mechanisms": False}))
    mechanisms = MechanismPlan(off, AblationPlan(off))
    assert not mechanisms.lammps and mechanisms.candidates(full=True) == {}
    assert mechanisms.settings("lammps", full=True) == [] and not mechanisms.table_made
    assert mechanisms.notes() == []


# ---- a figure: its module, its script, its rule ------------------------------------------


def rule_blocks() -> dict[str, str]:
    """Rule -> its text, as the rule files write it."""
    blocks = {}
    for path in sorted(RULES.glob("*.smk")):
        for match in re.finditer(r"^rule (\w+):\n.*?(?=^\S|\Z)", path.read_text(), re.M | re.S):
            blocks[match[1]] = match[0]
    return blocks


def test_a_figure_is_its_module_its_script_and_its_rule():
    """Each figure rule (outputs pdf and png named after it) runs workflow/scripts/<rule>.py,
    which draws with a module of chain.report.figures; its PNG is in the HTML report
    with a caption of its own; and a rule file publishes it (``publish_figure``: the run
    folder and the article)."""
    text = "\n".join(path.read_text() for path in sorted(RULES.glob("*.smk")))
    figures = {
        name: block
        for name, block in rule_blocks().items()
        if f"figures/{name}.pdf" in block and f"figures/{name}.png" in block
    }
    assert {"fig1_setup", "fig4_delay_vs_force", "ssw_spacetime"} <= set(figures), figures
    for name, block in figures.items():
        assert f'"../scripts/{name}.py"' in block, name
        script = ROOT / "workflow" / "scripts" / f"{name}.py"
        modules = {
            node.module
            for node in ast.walk(ast.parse(script.read_text()))
            if isinstance(node, ast.ImportFrom) and node.module
        }
        drawn = [m for m in modules if m.startswith("chain.report.figures.")]
        assert drawn, f"{script.name} draws with no module of chain.report.figures"
        for module in drawn:
            assert (ROOT / "src" / (module.replace(".", "/") + ".py")).is_file(), module
        assert re.search(r"png=report\(", block), name
        caption = re.search(r'caption="(\.\./report/[\w.]+\.rst)"', block)
        assert caption and (RULES / caption[1]).resolve().is_file(), name
        # Published by name, or as one of a tuple of names looped into publish_figure.
        assert re.search(rf'publish_figure\("{name}"\)', text) or re.search(
            rf'^for \w+ in \([^)]*"{name}"[^)]*\):\n\s+publish_figure\(\w+\)', text, re.M
        ), f"{name} is never published"
