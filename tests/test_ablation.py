"""Ablation of the virtual experiment: the switches that turn an apparatus ingredient
into the paper's simulation, and the config-driven variants
(chain.pipeline.config.ablation, chain.studies.ablation_table)."""

import collections
import copy
import dataclasses
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from snakemake.utils import validate

from chain.apparatus.virtual import VirtualExperiment, plan_shots, simulate_virtual_shots
from chain.errors import ConfigError, ParameterError
from chain.physics.builders import uniform_chain
from chain.physics.simulation import simulate
from chain.pipeline.config.ablation import (
    ablation_variants,
    check_ablation,
    variant_settings,
    variant_tolerance,
)
from chain.pipeline.config.virtual import virtual_experiment_settings
from chain.studies.ablation_table import ablation_table

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"

#: A small apparatus without imperfections.
SMALL = VirtualExperiment(
    n_beads=12,
    sensor_beads=(4, 9),
    impact_speeds_m_s=(0.1,),
    collision_shots=1,
    reference_shots=1,
    speed_mismatch=0.0,
    timing_jitter_s=0.0,
    noise_N=0.0,
    adc_bits=None,
    sampling_interval_s=1e-6,
    duration_s=0.6e-3,
    time_step_s=0.05e-6,
    seed=3,
)


@pytest.fixture(scope="module")
def paper():
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    validate(config, str(SCHEMA))
    return config


def test_bead_launch_with_point_readout_is_the_papers_simulation():
    """launch="bead" and readout="felt" make the apparatus model the paper's simulation:
    the same forces as chain.physics.simulation.simulate on a plain chain (same step),
    for a collision and a reference shot, with dissipation."""
    settings = dataclasses.replace(SMALL, launch="bead", readout="felt", eta_s=0.58e-6)
    plan = pd.DataFrame(
        {"kind": ["collision", "reference"], "v_left_m_s": 0.1, "v_right_m_s": [0.1, 0.0]}
    ).assign(delay_s=0.0)
    time, forces = simulate_virtual_shots(settings, plan)
    chain = uniform_chain(12, eta=0.58e-6)
    result = simulate(
        chain, [0.1, 0.1], [0.1, 0.0], duration=0.6e-3, dt=0.05e-6, record_interval=0.25e-6
    )
    expected = np.stack([result.force_felt(4), result.force_felt(9)], axis=1)
    assert time == pytest.approx(result.time)
    peak = expected.max()
    assert peak > 50  # ~100 N waves at 0.1 m/s
    assert np.max(np.abs(forces - expected)) < 1e-9 * peak


def test_split_sensor_reads_what_the_bead_feels():
    """The split-bead sensor reads the force felt by a plain bead to ~1 % of the peak
    (it is a stiff spring inside a bead of the same mass)."""
    plan = pd.DataFrame({"kind": ["reference"], "v_left_m_s": 1.0, "v_right_m_s": 0.0})
    plan = plan.assign(delay_s=0.0)
    _, sensor = simulate_virtual_shots(SMALL, plan)
    _, felt = simulate_virtual_shots(dataclasses.replace(SMALL, readout="felt"), plan)
    peak = felt.max()
    assert sensor.max() == pytest.approx(peak, rel=0.01)
    assert np.max(np.abs(sensor - felt)) < 0.05 * peak


def test_bead_launch_delay_is_a_gap_before_bead_n():
    """With launch="bead", a right launch d later (a gap v d before bead N) delays the
    RSTW by d at S2 and leaves the LSTW at S1 alone."""
    settings = dataclasses.replace(SMALL, launch="bead", readout="felt")
    plan = pd.DataFrame(
        {"kind": "collision", "v_left_m_s": 0.1, "v_right_m_s": 0.1, "delay_s": [0.0, 20e-6]}
    )
    time, forces = simulate_virtual_shots(settings, plan)
    early = time < 0.4e-3  # incident pulses only, before the waves cross

    def arrival(shot, sensor):
        return time[np.argmax(forces[shot, sensor] * early)]

    step = time[1] - time[0]
    assert arrival(1, 0) == pytest.approx(arrival(0, 0), abs=step)
    assert arrival(1, 1) - arrival(0, 1) == pytest.approx(20e-6, abs=step)


def test_reference_mismatch_switch_keeps_every_other_draw():
    """reference_speed_mismatch = 0 puts the reference shots at the nominal speed and
    leaves the collision shots' draws (speeds, delays, phases) as they were."""
    base = dataclasses.replace(
        SMALL,
        impact_speeds_m_s=(0.5, 1.0),
        collision_shots=3,
        reference_shots=2,
        speed_mismatch=0.02,
        timing_jitter_s=1e-5,
    )
    plan = plan_shots(base)
    nominal = plan_shots(dataclasses.replace(base, reference_speed_mismatch=0.0))
    ref = nominal["kind"] == "reference"
    assert nominal.loc[ref, "v_left_m_s"].tolist() == nominal.loc[ref, "nominal_speed_m_s"].tolist()
    assert not np.allclose(plan.loc[ref, "v_left_m_s"], plan.loc[ref, "nominal_speed_m_s"])
    pd.testing.assert_frame_equal(plan[~ref], nominal[~ref])
    assert plan["sampling_phase_s"].tolist() == nominal["sampling_phase_s"].tolist()


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        ({"readout": "point"}, "readout must be one of"),
        ({"launch": "cannon"}, "launch must be one of"),
        ({"reference_speed_mismatch": 0.7}, "reference_speed_mismatch"),
    ],
)
def test_bad_switches_are_named(change, fragment):
    plan = pd.DataFrame({"kind": ["reference"], "v_left_m_s": 1.0, "v_right_m_s": 0.0})
    with pytest.raises(ParameterError, match=fragment):
        simulate_virtual_shots(dataclasses.replace(SMALL, **change), plan.assign(delay_s=0.0))


# ----------------------------------------------------------------------------- config


def test_variants_map_config_keys(paper):
    variants = {v["name"]: v for v in ablation_variants(paper)}
    chain = paper["chains"][0]
    plain = virtual_experiment_settings(paper, chain["N"], chain["sensors"])
    assert variant_settings(paper, variants["as_configured"], chain["N"], chain["sensors"]) == plain
    again = variant_settings(paper, variants["as_configured"], chain["N"], chain["sensors"], 2)
    assert again["seed"] == plain["seed"] + 2000
    heavy = variant_settings(paper, variants["heavy_striker"], chain["N"], chain["sensors"])
    assert heavy["striker_radius"] == 0.013
    assert variant_settings(paper, variants["no_kuwabara_kono"], 25, [9, 17])["eta_s"] == 0.0
    assert variant_tolerance(paper, variants["no_selection"]) is None
    assert variant_tolerance(paper, variants["as_configured"]) == 0.05
    check_ablation(paper)


def with_variants(paper: dict, *variants: dict) -> dict:
    """The paper's config with ``ablation.variants``, schema defaults filled in; each
    variant's ``set`` goes in after validation, so that one the schema refuses reaches
    check_ablation (its second line of defence) all the same."""
    config = copy.deepcopy(paper)
    config["ablation"] = {"variants": [{"name": v["name"]} for v in variants]}
    validate(config, str(SCHEMA))
    for entry, variant in zip(config["ablation"]["variants"], variants, strict=True):
        entry["set"] = variant.get("set", {})
    return config


@pytest.mark.parametrize(
    ("variant", "fragment"),
    [
        ({"name": "a", "set": {"colour": 1}}, "ablation.variants[0].set.colour"),
        ({"name": "a", "set": {"noise_N": -1.0}}, "noise_N must be"),
        ({"name": "a", "set": {"collision_shots": 0}}, "collision_shots"),
    ],
)
def test_bad_variants_name_the_key(paper, variant, fragment):
    config = with_variants(paper, variant)
    with pytest.raises(ConfigError) as error:
        check_ablation(config)
    assert fragment in str(error.value)
    assert "ablation.variants[0]" in str(error.value)


def test_duplicate_variant_names_are_refused(paper):
    config = with_variants(paper, {"name": "a"}, {"name": "a"})
    with pytest.raises(ConfigError, match=r"ablation.variants\[1\].name"):
        check_ablation(config)


def test_ablation_table_keeps_the_runs_seed_and_the_spread_over_seeds():
    fits = pd.DataFrame(
        {
            "N": ["pooled"] * 3,
            "estimator": "fit_full",
            "C_us_N16": [43.0, 42.0, 44.0],
            "C_stderr_us_N16": [0.4, 0.5, 0.6],
            "exponent": [-0.21, -0.15, -0.16],
            "exponent_stderr": [0.01, 0.01, 0.01],
            "n_points": 78,
            "replicate": [0, 1, 2],
        }
    )
    table = ablation_table({"as_configured": fits}, {"as_configured": "none"})
    row = table.iloc[0]
    assert (row["C"], row["exponent"], row["n_seeds"]) == (43.0, -0.21, 3)
    assert row["exponent_seed_mean"] == pytest.approx(-0.52 / 3)
    assert row["C_seed_std"] == pytest.approx(1.0)
    assert row["series"] == "virtual experiment (model)"
    single = ablation_table({"x": fits[fits["replicate"] == 0]}, {})
    assert math.isnan(single.iloc[0]["exponent_seed_std"])


KINDS = {"collision", "reference"}


@pytest.mark.parametrize(
    ("change", "read", "integrated"),
    [
        ({}, "all", 0),  # the run itself: every shot read from its files
        ({"reference_speed_mismatch": 0.0}, "collision", 2),  # one reference per amplitude
        ({"noise_N": 0.0, "adc_bits": None}, "none", 6),  # the run's launches, other readings
        ({"speed_mismatch": 0.0, "timing_jitter_s": 0.0, "noise_N": 0.0}, "none", 4),
    ],
)
def test_shots_in_memory_are_those_a_dataset_holds(tmp_path, caplog, change, read, integrated):
    """A variant's shots made in memory (virtual_traces) are the trace table that loading
    the dataset the virtual experiment writes gives, to the bit (the files' 7 digits of
    volts included), whether a shot is integrated or read from the run's files (the same
    launch, draws and digitiser: reference_speed_mismatch moves the references only);
    and each distinct launch is integrated once (without mismatch or jitter the two
    collisions of an amplitude are one launch, and so is its reference)."""
    from chain.apparatus.measured import load_dataset
    from chain.apparatus.virtual import run_virtual_experiment
    from chain.apparatus.virtual_dataset import virtual_traces

    chains, datasets = written_datasets(tmp_path, seed=7)
    run = (VirtualExperiment.from_dict(chains[0]), datasets[0])
    settings = dataclasses.replace(run[0], **change)
    expected = load_dataset(run_virtual_experiment(settings, tmp_path / "v", "virtual"))
    caplog.set_level("INFO", logger="chain.physics.integrator")
    caplog.clear()
    known = {}
    traces = virtual_traces(settings, "virtual", known, run=run)
    pd.testing.assert_frame_equal(traces, expected, check_exact=True)
    digests = [d for r in caplog.records for d in r.getMessage().split(": ")[1].split()]
    assert len(digests) == len(set(digests)) == len(known) == integrated
    kinds = {launch[1] for launch in known}  # a launch: (chain, kind, ...)
    assert kinds == {"all": set(), "collision": {"reference"}}.get(read, KINDS)
    assert virtual_traces(settings, "virtual", known, run=run).equals(traces)
    assert len(known) == integrated  # the second time, every launch is known


def written_datasets(folder: Path, seed: int) -> tuple[list[dict], list[Path]]:
    """Two small virtual experiments (N = 16, 17; seeds ``seed`` + N) written as
    datasets under ``folder``: (their settings, their folders)."""
    from chain.apparatus.virtual import run_virtual_experiment

    chains = [
        {**virtual_experiment_settings_of(n, sensors), "seed": seed + n}
        for n, sensors in ((16, (5, 12)), (17, (5, 13)))
    ]
    datasets = [folder / f"N{c['n_beads']}" for c in chains]
    for fields, target in zip(chains, datasets, strict=True):
        run_virtual_experiment(VirtualExperiment.from_dict(fields), target, "virtual")
    return chains, datasets


def virtual_experiment_settings_of(n_beads: int, sensors) -> dict:
    """A small virtual experiment with every imperfection on (fields, plain values)."""
    settings = dataclasses.replace(
        SMALL,
        n_beads=n_beads,
        sensor_beads=tuple(sensors),
        impact_speeds_m_s=(1.0, 1.6),
        collision_shots=2,
        speed_mismatch=0.02,
        timing_jitter_s=1e-5,
        noise_N=0.1,
        adc_bits=12,
        sampling_interval_s=2e-6,
        duration_s=1.5e-3,
        time_step_s=2.5e-7,
    )
    return dataclasses.asdict(settings)


def test_the_tiny_run_integrates_each_launch_once(tiny_run):
    """Each collision of the tiny run is integrated by one job, once: the integrator
    names every launch it integrates by a digest of its chain, initial state, step and
    number of steps, and no digest appears twice in the logs of all the run's jobs (the
    simulations, the long chains, the virtual experiment, the ablation's shots, the C
    sensitivity's own eta). The jobs that read another's shots integrate none."""
    launches, logs = {}, tiny_run / "results" / "tiny" / "logs"
    for path in sorted(logs.rglob("*.log")):
        rule = path.relative_to(logs).parts[0].removesuffix(".log")
        for line in path.read_text().splitlines():
            if "chain.physics.integrator" in line and " launches: " in line:
                launches.setdefault(rule, []).extend(line.split(" launches: ")[1].split())
    integrating = {"simulate", "long_chain", "virtual_experiment", "ablation_shots",
                   "c_sensitivity_simulate"}  # fmt: skip
    assert integrating <= set(launches), sorted(launches)  # and lammps_check's kernel
    counted = collections.Counter(d for digests in launches.values() for d in digests)
    repeated = {d: n for d, n in counted.items() if n > 1}
    assert not repeated, f"{len(repeated)} of {len(counted)} launches integrated more than once"


def test_rows_of_an_estimator_need_the_column():
    from chain.analysis.rows import of_estimator

    table = pd.DataFrame({"estimator": ["peak", "fit_full", "peak"], "x": [1, 2, 3]})
    assert of_estimator(table, "peak")["x"].tolist() == [1, 3]
    assert list(of_estimator(table, "peak").index) == [0, 1]
    with pytest.raises(KeyError, match="estimator"):
        of_estimator(table.drop(columns="estimator"), "peak")
