"""Config bounds: every value outside a key's range stops the run
before any job, naming the key; the values at the bounds pass; docs/config_bounds.md is
the table the schema and chain.pipeline.config.bounds_table.RULES give.

Each case changes the tiny config (tests/configs/tiny.yaml on config.yaml) and runs the
checks the Snakefile runs (schema, then check_config); one case goes through Snakemake.
"""

from __future__ import annotations

import copy
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import update_config, validate

from chain.pipeline.config.bounds import variant_config
from chain.pipeline.config.bounds_table import CHOICE, RULES, bounds_table, table_rows
from chain.pipeline.config.check import ConfigError, check_config

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


@pytest.fixture(scope="module")
def tiny() -> dict:
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    update_config(config, yaml.safe_load((ROOT / "tests" / "configs" / "tiny.yaml").read_text()))
    return config


@pytest.fixture(scope="module")
def plain(tiny) -> dict:
    """The tiny config without the ablation variants (each variant is checked with its
    own settings, so a run bound would be reached through a variant first)."""
    return {**copy.deepcopy(tiny), "ablation": {"variants": []}}


def outcome(config: dict, overlay: dict) -> str | None:
    """The message that stops ``config`` with ``overlay`` merged, or None if it passes."""
    config = copy.deepcopy(config)
    update_config(config, overlay)
    try:
        validate(config, str(SCHEMA))
        check_config(config)
    except (WorkflowError, ConfigError) as error:
        return str(error)
    return None


def named(message: str, path: tuple) -> bool:
    dotted = ""
    for part in path:
        dotted += f"[{part}]" if isinstance(part, int) else (f".{part}" if dotted else part)
    instance = "instance" + "".join(f"[{p!r}]" for p in path)
    return f"'{dotted}'" in message or instance in message


def nest(path: tuple, value) -> dict:
    """{a: {b: value}} from ("a", "b") (lists are replaced whole by update_config)."""
    for part in reversed(path):
        value = {part: value}
    return value


TINY_STRIKERS = {"impact_speeds_m_s": [1.0, 1.6, 2.5]}

#: name -> (key path named, value just outside, value at the bound or just inside).
#: Values in the tiny config: N = 16, 17; launch 0.1..1 m/s; strikers 1..2.5 m/s.
BOUNDS = {
    "launch.count >= 3 (free exponent)": (("launch", "count"), 2, 3),
    "launch.count <= 200": (("launch", "count"), 201, 200),
    "impact speeds: 3": (
        ("experiment", "virtual", "impact_speeds_m_s"),
        [1.0, 2.5],
        [1.0, 1.6, 2.5],
    ),
    "impact speeds distinct": (
        ("experiment", "virtual", "impact_speeds_m_s"),
        [1.0, 1.0, 2.5],
        [1.0, 1.01, 2.5],
    ),
    "check speeds distinct": (("lammps", "check_speeds_m_s"), [0.1, 0.1], [0.1, 0.3]),
    "sweep speeds distinct": (
        ("lammps", "sweep", "launch_speeds_m_s"),
        [0.1, 0.1],
        [0.1, 0.3],
    ),
    "traces_N distinct": (("figures", "traces_N"), [16, 16], [16, 17]),
    "max_energy_drift <= 0.01": (("simulation", "max_energy_drift"), 0.02, 0.01),
    "max_energy_drift >= default step's": (("simulation", "max_energy_drift"), 5e-10, 1e-9),
    "record interval: whole steps": (
        ("simulation", "record_interval_s"),
        {"time_step_s": 4e-7, "record_interval_s": 1e-6},
        {"time_step_s": 2.5e-7, "record_interval_s": 1e-6},
    ),
    "record interval resolves the pulse": (
        ("simulation", "record_interval_s"),
        {"record_interval_s": 2e-5},
        {"record_interval_s": 1e-5},
    ),
    "long chains: waves collide": (("long_chains", "duration_s"), 1.0e-3, 1.2e-3),
    "lammps: whole steps": (("lammps", "record_interval_s"), 1.01e-6, 1.025e-6),
    "lammps: resolves the pulse": (("lammps", "record_interval_s"), 2e-5, 1e-5),
    "lammps: 10 samples": (
        ("lammps", "duration_s"),
        {"duration_s": 1e-4, "record_interval_s": 1.25e-5},
        {"duration_s": 1.5e-3, "record_interval_s": 1.25e-5},
    ),
    "lammps: waves pass the sensors": (("lammps", "duration_s"), 6e-4, 1e-3),
    "friction named apart": (
        ("lammps", "sweep", "track_friction", 1),
        [0.3, 0.303],
        [0.3, 0.31],
    ),
    "friction not named frictionless": (
        ("lammps", "sweep", "default_settings", 0),
        [[0.004, 0.0]],
        [[0.01, 0.0]],
    ),
    "viscous named apart": (
        ("lammps", "sweep", "viscous_N_s_per_m", 1),
        [10.0, 10.0000001],
        [10.0, 10.001],
    ),
    "sampling resolves the pulse": (
        ("experiment", "virtual", "sampling_interval_s"),
        {"sampling_interval_s": 3e-5},
        {"sampling_interval_s": 1e-5},
    ),
    "sensor S1 2 beads left of the collision point": (
        ("chains", 0, "sensors", 0),
        [{"N": 16, "sensors": [7, 12]}, {"N": 17, "sensors": [5, 13]}],
        [{"N": 16, "sensors": [6, 12]}, {"N": 17, "sensors": [5, 13]}],
    ),
    "sensor S2 2 beads right of the collision point": (
        ("chains", 0, "sensors", 1),
        [{"N": 16, "sensors": [5, 10]}, {"N": 17, "sensors": [5, 13]}],
        [{"N": 16, "sensors": [5, 11]}, {"N": 17, "sensors": [5, 13]}],
    ),
    # N = 5 ([1, 5]) leaves the launch jitter no room: N = 6 with the virtual experiment.
    "N >= 5": (("chains", 0, "N"), [{"N": 4, "sensors": [1, 4]}], [{"N": 6, "sensors": [1, 6]}]),
    "seed <= 2^62": (("seed",), 2**62 + 1, 2**62),
    "model name <= 100 characters": (
        ("models", 0, "name"),
        [{"name": "e" * 101, "eta_s": 0.0}, {"name": "viscoelastic", "eta_s": 0.58e-6}],
        [{"name": "e" * 100, "eta_s": 0.0}, {"name": "viscoelastic", "eta_s": 0.58e-6}],
    ),
    "long chains <= 1 s": (("long_chains", "duration_s"), 1.01, 1.0),
    "lammps duration <= 1 s": (("lammps", "duration_s"), 1.01, 1.0),
    "tolerance > 0": (("experiment", "tolerance"), 0.0, 0.05),
    "tolerance keeps 2 shots (planned speeds)": (("experiment", "tolerance"), 0.008, 0.0082),
    "drag leaves the smallest pulse detectable": (
        ("experiment", "virtual", "drag_rate_per_s"),
        2900.0,
        2800.0,
    ),
    "ADC step under the smallest pulse": (
        ("experiment", "virtual", "adc_range_V"),
        {"adc_range_V": 90.0},
        {"adc_range_V": 88.0},
    ),
    "sensor spring resolved by the given step": (
        ("experiment", "virtual", "sensor_stiffness_N_per_m"),
        4.6e9,
        4.5e9,
    ),
    "right delay keeps the collision between the sensors": (
        ("experiment", "virtual", "right_delay_s"),
        {"right_delay_s": 1.9e-4, "timing_jitter_s": 0.0},
        {"right_delay_s": 1.8e-4, "timing_jitter_s": 0.0},
    ),
    "noise below the smallest pulse": (
        ("experiment", "virtual", "noise_N"),
        {"noise_N": 3.9, "adc_bits": None},
        {"noise_N": 3.8, "adc_bits": None},
    ),
}


def overlay_of(path: tuple, value) -> dict:
    """The overlay that sets ``value``: a dict value sets several keys of the section."""
    keys = tuple(p for p in path if not isinstance(p, int))
    if isinstance(value, list) and value and isinstance(value[0], dict):
        return {keys[0]: value}  # the whole list of chains or models
    if isinstance(value, dict):
        return nest(keys[:-1], value)
    return nest(keys, value)


@pytest.mark.parametrize(("path", "outside", "inside"), BOUNDS.values(), ids=BOUNDS)
def test_value_outside_is_stopped_naming_the_key(plain, path, outside, inside):
    message = outcome(plain, overlay_of(path, outside))
    assert message is not None, "accepted"
    assert named(message, path), message
    assert outcome(plain, overlay_of(path, inside)) is None


def test_every_variant_is_checked_with_its_settings(tiny):
    """`studies.ablation: full` runs every variant, not only those of the default run."""
    variants = [{"name": "slow", "set": {"duration_s": 2e-4}}]
    message = outcome(tiny, {"ablation": {"variants": variants}})
    assert "config key 'ablation.variants[0].set' (variant 'slow')" in message
    assert "experiment.virtual.duration_s" in message
    variants[0]["set"]["duration_s"] = 1.5e-3
    assert outcome(tiny, {"ablation": {"variants": variants}}) is None


def test_bead_launch_duration_is_the_launched_beads(tiny):
    """launch: bead launches the end beads at V0 (no 4 mm striker, whose wave is ~30 x
    smaller): its duration is the simulation's, not the strikers'."""
    bead = {"launch": "bead", "impact_speeds_m_s": [0.021, 0.05, 0.1]}
    variants = [{"name": "bead", "set": {**bead, "duration_s": 1.25e-3}}]
    message = outcome(tiny, {"ablation": {"variants": variants}})
    assert "(variant 'bead')" in message and "experiment.virtual.duration_s" in message
    variants[0]["set"]["duration_s"] = 1.35e-3
    assert outcome(tiny, {"ablation": {"variants": variants}}) is None


def test_heavy_striker_bounces_less(tiny):
    """A striker of the beads' mass hands on its momentum m_s V0 and stops (an elastic
    bounce gives 2 m_s m / (m_s + m) V0): the paper's heavy_striker variant reads
    ~1 V at 0.13 m/s, under the 2 V of its ADC."""
    heavy = {"striker_radius_m": 0.013, "impact_speeds_m_s": [0.021, 0.05, 0.13]}
    assert outcome(tiny, {"ablation": {"variants": [{"name": "h", "set": heavy}]}}) is None
    heavy["impact_speeds_m_s"] = [0.05, 0.1, 0.3]
    message = outcome(tiny, {"ablation": {"variants": [{"name": "h", "set": heavy}]}})
    assert "experiment.virtual.adc_range_V" in message


def test_variant_config_applies_the_overrides(tiny):
    config = copy.deepcopy(tiny)
    validate(config, str(SCHEMA))
    derived = variant_config(config, {"striker_radius_m": 0.013, "noise_N": 0.0, "tolerance": None})
    assert derived["setup"]["striker_radius_m"] == 0.013
    assert derived["experiment"]["virtual"]["noise_N"] == 0.0
    assert derived["experiment"]["tolerance"] is None  # no selection: nothing to bound
    assert derived["ablation"]["variants"] == [] and config["ablation"]["variants"]


def test_table_is_generated_from_schema_and_rules():
    schema = yaml.safe_load(SCHEMA.read_text())
    table = bounds_table(schema)
    assert (ROOT / "docs" / "config_bounds.md").read_text() == table, (
        "regenerate: python -m chain.pipeline.config.bounds_table "
        "workflow/schemas/config.schema.yaml > docs/config_bounds.md"
    )
    keys = {line.split("`")[1] for line in table.splitlines() if line.startswith("| `")}
    assert set(RULES) <= keys, sorted(set(RULES) - keys)


def test_every_key_has_a_largest_value_or_a_reason():
    """A smallest and a largest usable value per key; where the schema
    has no largest, RULES says what bounds it or why nothing does."""
    rows = table_rows(yaml.safe_load(SCHEMA.read_text()))
    blank = [key for key, _, kind, _, upper, rule in rows if not upper and not rule]
    assert blank == [], blank
    choices = {key: upper for key, _, kind, _, upper, _ in rows if kind == "boolean"}
    assert set(choices.values()) == {CHOICE}


def test_snakemake_dry_run_refuses_before_any_job(tmp_path):
    """launch.count 1 (equal speeds) once started 33 jobs of the tiny run and wrote
    simulations before c_sensitivity failed in scipy; now the DAG is never built."""
    name = "bad_count_bounds"
    overlay = tmp_path / "bad.yaml"
    overlay.write_text(
        f"run_name: {name}\nlaunch: {{v0_min_m_s: 0.5, v0_max_m_s: 0.5, count: 1}}\n"
    )
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--cores", "1", "--configfile", str(overlay)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    console = result.stdout + result.stderr
    assert result.returncode != 0
    assert "instance['launch']['count']" in console, console[-2000:]
    assert "rule simulate" not in console
    assert not (ROOT / "results" / name).exists()
