"""The pipeline's config: the JSON schema (workflow/schemas/config.schema.yaml), the
semantic checks of chain.pipeline.config.check, and the shipped configs (config.yaml, whatif/).

A bad config must stop before any job runs, with a message naming the key.
"""

from __future__ import annotations

import copy
import functools
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import update_config, validate

from chain.analysis.pulses import ESTIMATORS
from chain.errors import ConfigError, key_label
from chain.physics.materials import MATERIALS
from chain.pipeline.config.check import check_config
from chain.pipeline.plan.datasets import experiment_parts

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
OVERLAYS = sorted((ROOT / "whatif").glob("*.yaml")) + sorted(
    (ROOT / "tests" / "configs").glob("*.yaml")
)


def load(path: Path) -> dict:
    """The YAML file ``path``, a copy of its parse (the checkout's files do not change
    during a session; config.yaml takes ~15 ms to parse and most tests start from it)."""
    return copy.deepcopy(_parsed(path))


@functools.cache
def _parsed(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


@pytest.fixture()
def paper() -> dict:
    """config.yaml, as loaded (before defaults)."""
    return load(ROOT / "config.yaml")


def validated(config: dict) -> dict:
    config = copy.deepcopy(config)
    validate(config, str(SCHEMA))
    return config


def schema_error(config: dict) -> str:
    """The message snakemake.utils.validate gives for ``config``."""
    with pytest.raises(WorkflowError) as error:
        validate(copy.deepcopy(config), str(SCHEMA))
    return str(error.value)


def instance(*path) -> str:
    """How jsonschema (and so Snakemake) names a key: instance['chains'][1]['N']."""
    return "instance" + "".join(f"[{p!r}]" for p in path)


# ---- the shipped configs ------------------------------------------------------------


def test_paper_config_is_valid_and_complete(paper):
    config = validated(paper)
    check_config(config)
    assert config["run_name"] == "paper"
    assert config["radius_m"] == 0.013
    assert [c["N"] for c in config["chains"]] == [25, 26]
    assert {c["N"]: c["sensors"] for c in config["chains"]} == {25: [9, 17], 26: [10, 17]}
    assert {m["name"]: m["eta_s"] for m in config["models"]} == {
        "elastic": 0.0,
        "viscoelastic": 0.58e-6,
    }
    assert config["simulation"]["duration_s"] == 2.6e-3
    assert config["simulation"]["time_step_s"] is None


@pytest.mark.parametrize("overlay", OVERLAYS, ids=lambda p: p.name)
def test_overlays_merge_into_valid_configs(paper, overlay):
    """What-if overlays only carry the keys they change (snakemake --configfile merges)."""
    config = copy.deepcopy(paper)
    update_config(config, load(overlay))
    config = validated(config)
    check_config(config)
    assert config["run_name"] != "paper", "an overlay must not write into results/paper/"


def test_parity_overlay_places_sensors_symmetrically():
    chains = load(ROOT / "whatif" / "parity.yaml")["chains"]
    assert [c["N"] for c in chains] == list(range(20, 32))
    for chain in chains:
        s1, s2 = chain["sensors"]
        assert s1 + s2 == chain["N"] + 1, chain


def test_defaults_are_filled(paper):
    minimal = {k: paper[k] for k in ("run_name", "material", "radius_m", "chains", "models")}
    minimal["launch"] = paper["launch"]
    config = validated(minimal)
    assert config["simulation"]["record_interval_s"] == 1e-6
    assert config["analysis"]["estimators"] == ["fit_full", "peak", "fit_rise"]
    assert config["figures"]["traces_model"] == "viscoelastic"
    assert config["figures"]["parity_ssw_vs_N"] is False
    experiment = config["experiment"]
    assert experiment["source"] == "virtual" and experiment["tolerance"] == 0.05
    assert experiment["datasets"] == [] and experiment["name"] is None
    assert experiment["virtual"]["collision_shots"] == 3
    assert experiment["virtual"]["reference_shots"] == 2
    assert experiment["virtual"]["impact_speeds_m_s"] is None
    assert experiment["virtual"]["sensor_stiffness_N_per_m"] == 1.9e9


def test_paper_experiment_is_the_virtual_one_and_modest(paper):
    """The paper run's virtual experiment: >= 3 collision and >= 2 reference shots at
    each of 8-10 amplitudes (the rebuild stays within its time budget)."""
    virtual = validated(paper)["experiment"]["virtual"]
    assert validated(paper)["experiment"]["source"] == "virtual"
    assert 8 <= len(virtual["impact_speeds_m_s"]) <= 10
    assert virtual["collision_shots"] >= 3 and virtual["reference_shots"] >= 2


def test_virtual_settings_map_onto_the_virtual_experiment(paper):
    from dataclasses import fields

    from chain.apparatus.virtual import VirtualExperiment
    from chain.pipeline.config.virtual import VIRTUAL_KEYS, virtual_experiment

    # The config's keys are the fields' names: experiment.virtual passes on as it is.
    schema = load(SCHEMA)["properties"]["experiment"]["properties"]["virtual"]["properties"]
    assert set(VIRTUAL_KEYS) == set(schema)
    assert set(VIRTUAL_KEYS) < {f.name for f in fields(VirtualExperiment)}
    config = validated(paper)
    settings = virtual_experiment(config, 26, [10, 17])
    assert settings.n_beads == 26 and settings.sensor_beads == (10, 17)
    assert settings.seed == config["seed"] + 26
    assert settings.striker_radius == config["setup"]["striker_radius_m"] == 0.004
    assert settings.radius == 0.013 and settings.material == "steel_100C6"
    assert settings.eta_s == 0.58e-6 and settings.sensor_stiffness_N_per_m == 1.9e9
    assert settings.collision_shots == 3 and settings.reference_shots == 2


def test_experiment_parts_and_labels(paper):
    from chain.pipeline.plan.datasets import experiment_label

    config = validated(paper)
    virtual = experiment_parts(config)
    assert [(p.name, p.n_beads, p.sensor_beads, p.folder) for p in virtual] == [
        ("virtual", 25, (9, 17), None),
        ("virtual", 26, (10, 17), None),
    ]
    assert experiment_label(virtual) == "virtual experiment (model)"
    config["experiment"] = {**config["experiment"], "source": "none"}
    assert experiment_parts(config) == [] and experiment_label([]) == "experiment"
    config["experiment"] = {
        **config["experiment"],
        "source": "measured",
        "datasets": [SMALL],
    }
    (part,) = experiment_parts(config, root=ROOT)
    assert (part.name, part.n_beads, part.sensor_beads) == ("virtual_small", 25, (9, 17))
    assert part.files[0] == f"{SMALL}/metadata.yaml" and len(part.files) == 7
    # Written by the virtual experiment: still labelled as a model, with its name.
    assert experiment_label([part]) == "virtual experiment (model): virtual_small"
    lab = type(part)("lab2011", 25, (9, 17), "data/lab2011_N25", (), virtual=False)
    assert experiment_label([lab]) == "measured (lab2011)"
    config["experiment"]["name"] = "rig"
    assert experiment_parts(config, root=ROOT)[0].name == "rig"


def test_duration_check_has_margin_on_the_shipped_configs(paper):
    """The estimate behind the duration check, against the paper run: the slowest
    simulated wave (0.021 m/s) and striker wave (0.4 m/s) of the N = 26 chain."""
    from chain.physics.theory import pulse_passing_time
    from chain.pipeline.config.check import DURATION_MARGIN

    slow = pulse_passing_time("steel_100C6", 0.013, 26, [10, 17], 0.021)
    # The simulation measures F_m = 10.0 N; the estimate is a little lower (slower).
    assert 9.0 < slow["force_N"] < 10.0
    assert slow["distance_m"] == pytest.approx(16 * 0.026)
    assert DURATION_MARGIN * slow["time_s"] < 2.6e-3
    striker = pulse_passing_time("steel_100C6", 0.013, 26, [10, 17], 0.4, (4 / 13) ** 3)
    # The virtual experiment measures ~10 N at 0.4 m/s; momentum m_s V0 bounds it below.
    assert 3.0 < striker["force_N"] < 10.0
    assert DURATION_MARGIN * striker["time_s"] < 2.4e-3


def test_schema_enums_follow_the_library():
    schema = load(SCHEMA)
    assert set(schema["properties"]["material"]["enum"]) == set(MATERIALS)
    analysis = schema["properties"]["analysis"]["properties"]
    assert set(analysis["estimators"]["items"]["enum"]) == set(ESTIMATORS)
    assert set(analysis["main_estimator"]["enum"]) == set(ESTIMATORS)


def _walk(schema: dict, path=()):
    for name, sub in schema.get("properties", {}).items():
        yield (*path, name), sub
        yield from _walk(sub, (*path, name))
    items = schema.get("items")
    if isinstance(items, dict):
        yield from _walk(items, (*path, "[]"))


def test_every_key_is_described_and_closed():
    schema = load(SCHEMA)
    assert schema["additionalProperties"] is False
    for path, sub in _walk(schema):
        assert sub.get("description"), f"{'.'.join(path)} has no description"
        if sub.get("type") == "object":
            assert sub.get("additionalProperties") is False, ".".join(path)


# ---- bad configs: each is stopped with a message naming the key and what is allowed -----


def config_error(config: dict) -> str:
    """The message that stops ``config``: the schema's (snakemake.utils.validate), else
    chain.pipeline.config.check' (check_config, then experiment_parts, as the Snakefile runs
    them); fails the test if the config passes."""
    config = copy.deepcopy(config)
    try:
        validate(config, str(SCHEMA))
        check_config(config)
        experiment_parts(config, root=ROOT)
    except (WorkflowError, ConfigError) as error:
        return str(error)
    pytest.fail("the config was accepted")


def key(name: str) -> str:
    """How chain.pipeline.config.check names a key."""
    return f"config key '{name}': "


def on(*path) -> str:
    """How the schema check names a key: On instance['chains'][1]['N']:"""
    return f"On {instance(*path)}:"


def setter(*path, value=None, drop=False):
    """A change to the config: set (or drop) the key at ``path``."""

    def change(config):
        target = config
        for part in path[:-1]:
            target = target.setdefault(part, {}) if isinstance(part, str) else target[part]
        if drop:
            del target[path[-1]]
        else:
            target[path[-1]] = value

    return change


def measured(*folders, **extra):
    """Point the experiment at measured dataset folders (relative to the repository)."""
    return setter("experiment", value={"source": "measured", "datasets": list(folders), **extra})


SMALL = "tests/data/virtual_small"

#: item of the issue -> (change, key named, what the message says is allowed / wrong).
BAD_CONFIGS = {
    # -- types, ranges and unknown keys (the schema) --
    "N >= 5": (
        setter("chains", 0, "N", value=4),
        on("chains", 0, "N"),
        "less than the minimum of 5",
    ),
    "N an integer": (
        setter("chains", 1, "N", value="26"),
        on("chains", 1, "N"),
        "is not of type 'integer'",
    ),
    "two sensors": (
        setter("chains", 0, "sensors", value=[9]),
        on("chains", 0, "sensors"),
        "is too short",
    ),
    "sensor bead >= 1": (
        setter("chains", 0, "sensors", value=[0, 17]),
        on("chains", 0, "sensors", 0),
        "less than the minimum of 1",
    ),
    "radius > 0": (
        setter("radius_m", value=-0.013),
        on("radius_m"),
        "less than or equal to the minimum of 0",
    ),
    "speed > 0": (
        setter("launch", "v0_min_m_s", value=0.0),
        on("launch", "v0_min_m_s"),
        "less than or equal to the minimum of 0",
    ),
    "count >= 3": (
        setter("launch", "count", value=2),
        on("launch", "count"),
        "less than the minimum of 3",
    ),
    "time step > 0": (
        setter("simulation", "time_step_s", value=0.0),
        on("simulation", "time_step_s"),
        "less than or equal to the minimum of 0",
    ),
    "record interval > 0": (
        setter("simulation", "record_interval_s", value=-1e-6),
        on("simulation", "record_interval_s"),
        "less than or equal to the minimum of 0",
    ),
    "duration a number": (
        setter("simulation", "duration_s", value="long"),
        on("simulation", "duration_s"),
        "is not of type 'number'",
    ),
    "eta >= 0": (
        setter("models", 1, "eta_s", value=-1e-7),
        on("models", 1, "eta_s"),
        "less than the minimum of 0",
    ),
    "model needs eta": (
        setter("models", 1, "eta_s", drop=True),
        on("models", 1),
        "'eta_s' is a required property",
    ),
    "known material (schema)": (
        setter("material", value="granite"),
        on("material"),
        "'granite' is not one of ['steel_100C6', 'brass', 'stainless_316']",
    ),
    "known estimator": (
        setter("analysis", "estimators", value=["fit_full", "median"]),
        on("analysis", "estimators", 1),
        "'median' is not one of",
    ),
    "model name safe": (
        setter("models", 0, "name", value="my_model"),
        on("models", 0, "name"),
        "does not match",
    ),
    "run_name safe: slash": (
        setter("run_name", value="my run/1"),
        on("run_name"),
        "does not match '^[A-Za-z0-9][A-Za-z0-9_.-]*$'",
    ),
    "run_name safe: dot-dot": (setter("run_name", value=".."), on("run_name"), "does not match"),
    "run_name safe: empty": (setter("run_name", value=""), on("run_name"), "does not match"),
    "run_name safe: length": (setter("run_name", value="r" * 101), on("run_name"), "is too long"),
    "unknown key, top level": (setter("radius", value=0.013), on(), "'radius' was unexpected"),
    "unknown key, nested": (
        setter("launch", "v0_m_s", value=1.0),
        on("launch"),
        "'v0_m_s' was unexpected",
    ),
    "flag a boolean": (
        setter("figures", "parity_ssw_vs_N", value="yes"),
        on("figures", "parity_ssw_vs_N"),
        "is not of type 'boolean'",
    ),
    # -- relations between keys (chain.pipeline.config.check.check_config) --
    "sensor inside 1..N": (
        setter("chains", 0, "sensors", value=[9, 30]),
        key("chains[0].sensors[1]"),
        "bead 30 is outside the chain; allowed: beads 1..25",
    ),
    "sensors in order": (
        setter("chains", 1, "sensors", value=[17, 10]),
        key("chains[1].sensors"),
        "got [17, 10]; allowed: S1 left of S2",
    ),
    "unique N": (
        setter("chains", 1, "N", value=25),
        key("chains[1].N"),
        "N = 25 is listed twice (also chains[0]); allowed: each N once",
    ),
    "long chain not a chain": (
        setter("long_chains", "N", value=[26, 121]),
        key("long_chains.N[0]"),
        "N = 26 is also chains[1] (their files would clash)",
    ),
    "long chain long enough": (
        setter("long_chains", "N", value=[2]),
        on("long_chains", "N", 0),
        "less than the minimum of 26",
    ),
    "unique model names": (
        setter("models", 1, "name", value="elastic"),
        key("models[1].name"),
        "'elastic' is listed twice; allowed: each name once",
    ),
    "v0_min <= v0_max": (
        setter("launch", "v0_min_m_s", value=2.0),
        key("launch.v0_min_m_s"),
        "allowed: v0_min_m_s <= v0_max_m_s",
    ),
    "several speeds need a range": (
        setter("launch", "v0_max_m_s", value=0.021),
        key("launch.count"),
        "12 launch speeds need v0_min_m_s < v0_max_m_s",
    ),
    "time step <= record interval": (
        setter("simulation", "time_step_s", value=1e-5),
        key("simulation.time_step_s"),
        "1e-05 s is longer than record_interval_s = 1e-06 s",
    ),
    "duration: samples": (
        setter("simulation", "duration_s", value=5e-6),
        key("simulation.duration_s"),
        "holds fewer than 10 samples",
    ),
    "duration: waves pass the far sensor": (
        setter("simulation", "duration_s", value=1.5e-3),
        key("simulation.duration_s"),
        "0.0015 s is too short: the slowest wave (bead 1 launched at V0 = 0.021 m/s",
    ),
    "main estimator among estimators": (
        setter("analysis", "estimators", value=["peak"]),
        key("analysis.main_estimator"),
        "'fit_full' is not among analysis.estimators; allowed: ['peak']",
    ),
    "Fig. 3 model configured": (
        setter("figures", "traces_model", value="plastic"),
        key("figures.traces_model"),
        "allowed: ['elastic', 'viscoelastic']",
    ),
    "Fig. 2/3 chains configured": (
        setter("figures", "traces_N", value=[25, 27]),
        key("figures.traces_N[1]"),
        "N = 27 is not a configured chain; allowed: [25, 26]",
    ),
    "amplitude index in range": (
        setter("figures", "representative_index", value=12),
        key("figures.representative_index"),
        "allowed: 0..11",
    ),
    # -- the experiment (schema, then check_config and experiment_parts) --
    "experiment source known": (
        setter("experiment", "source", value="lab"),
        on("experiment", "source"),
        "'lab' is not one of ['virtual', 'measured', 'none']",
    ),
    "tolerance a fraction": (
        setter("experiment", "tolerance", value=5),
        on("experiment", "tolerance"),
        "greater than the maximum of 1",
    ),
    "experiment name safe": (
        setter("experiment", "name", value="lab 2011"),
        on("experiment", "name"),
        "does not match",
    ),
    "virtual: unknown key": (
        setter("experiment", "virtual", "eta", value=1e-6),
        on("experiment", "virtual"),
        "'eta' was unexpected",
    ),
    "virtual: impact speeds > 0": (
        setter("experiment", "virtual", "impact_speeds_m_s", value=[0.4, -1.0, 1.0]),
        on("experiment", "virtual", "impact_speeds_m_s", 1),
        "less than or equal to the minimum of 0",
    ),
    "virtual: a collision shot": (
        setter("experiment", "virtual", "collision_shots", value=0),
        on("experiment", "virtual", "collision_shots"),
        "less than the minimum of 1",
    ),
    "virtual: a reference shot": (
        setter("experiment", "virtual", "reference_shots", value=0),
        on("experiment", "virtual", "reference_shots"),
        "less than the minimum of 1",
    ),
    "virtual: mismatch < 0.5": (
        setter("experiment", "virtual", "speed_mismatch", value=0.5),
        on("experiment", "virtual", "speed_mismatch"),
        "greater than or equal to the maximum of 0.5",
    ),
    "virtual: sampling > 0": (
        setter("experiment", "virtual", "sampling_interval_s", value=0),
        on("experiment", "virtual", "sampling_interval_s"),
        "less than or equal to the minimum of 0",
    ),
    "virtual: speeds or heights": (
        setter("experiment", "virtual", "drop_heights_m", value=[0.05, 0.1, 0.2]),
        key("experiment.virtual.drop_heights_m"),
        "give impact_speeds_m_s or drop_heights_m, not both",
    ),
    "virtual: duration samples": (
        setter("experiment", "virtual", "duration_s", value=5e-6),
        key("experiment.virtual.duration_s"),
        "holds fewer than 10 samples",
    ),
    "virtual: time step <= sampling": (
        setter("experiment", "virtual", "time_step_s", value=3e-6),
        key("experiment.virtual.time_step_s"),
        "allowed: <= the sampling interval, or null",
    ),
    "virtual: duration for the waves": (
        setter("experiment", "virtual", "duration_s", value=1.5e-3),
        key("experiment.virtual.duration_s"),
        "0.0015 s is too short: the slowest wave (striker at 0.4 m/s",
    ),
    "virtual: ADC range": (
        setter("experiment", "virtual", "adc_range_V", value=0.5),
        key("experiment.virtual.adc_range_V"),
        "would saturate the ADC; allowed: >",
    ),
    "measured needs datasets": (
        setter("experiment", "source", value="measured"),
        key("experiment.datasets"),
        "source: measured needs at least one dataset folder",
    ),
    "datasets only when measured": (
        setter("experiment", "datasets", value=[SMALL]),
        key("experiment.datasets"),
        "read only with source: measured (source is 'virtual')",
    ),
    "dataset folder exists": (
        measured("data/no_such_lab"),
        key("experiment.datasets[0]"),
        "data/no_such_lab: no such dataset folder",
    ),
    "each dataset once": (
        measured(SMALL, SMALL),
        on("experiment", "datasets"),
        "has non-unique elements",
    ),
    "dataset name and N once": (
        measured(SMALL, "tests/data/../data/virtual_small"),
        key("experiment.datasets[1]"),
        "gives the series 'virtual_small' with N = 25 again",
    ),
}


@pytest.mark.parametrize(("change", "where", "message"), BAD_CONFIGS.values(), ids=BAD_CONFIGS)
def test_bad_config_is_stopped_naming_the_key(paper, change, where, message):
    config = copy.deepcopy(paper)
    change(config)
    error = config_error(config)
    assert where in error, error
    assert message in error, error


def test_key_label():
    assert key_label(["chains", 0, "sensors", 1]) == "chains[0].sensors[1]"
    assert key_label([]) == "<top level>"


@pytest.mark.parametrize(
    ("overlay", "key"),
    [
        ("run_name: bad\nchains:\n  - {N: 25, sensors: [9, 40]}\n", "chains[0].sensors[1]"),
        ("run_name: bad\nradius_m: -1\n", "instance['radius_m']"),
        (
            "run_name: bad\nexperiment: {source: measured, datasets: [data/no_such_lab]}\n",
            "config key 'experiment.datasets[0]': data/no_such_lab: no such dataset folder",
        ),
    ],
)
def test_bad_config_stops_snakemake_before_any_job(tmp_path, overlay, key):
    """The Snakefile validates at parse time: a dry run fails and names the key."""
    bad = tmp_path / "bad.yaml"
    bad.write_text(overlay)
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "--configfile", str(bad)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode != 0
    output = result.stdout + result.stderr
    assert key in output
    assert "rule simulate" not in output
    assert "rule virtual_experiment" not in output
