"""Config bounds (issue 32, item 3): every value outside a key's range stops the run
before any job, naming the key; the values at the bounds pass; docs/config_bounds.md is
the table the schema and chain.pipeline.config_bounds.RULES give.

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

from chain.pipeline.config import ConfigError, check_config
from chain.pipeline.config_bounds import RULES, bounds_table, variant_config

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


@pytest.fixture(scope="module")
def tiny() -> dict:
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    update_config(config, yaml.safe_load((ROOT / "tests" / "configs" / "tiny.yaml").read_text()))
    return config


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
    "noise below the smallest pulse": (
        ("experiment", "virtual", "noise_N"),
        {"noise_N": 4.0, "adc_bits": None},
        {"noise_N": 3.9, "adc_bits": None},
    ),
}


def overlay_of(path: tuple, value) -> dict:
    """The overlay that sets ``value``: a dict value sets several keys of the section."""
    keys = tuple(p for p in path if not isinstance(p, int))
    if isinstance(value, dict):
        return nest(keys[:-1], value)
    return nest(keys, value)


@pytest.mark.parametrize(("path", "outside", "inside"), BOUNDS.values(), ids=BOUNDS)
def test_value_outside_is_stopped_naming_the_key(tiny, path, outside, inside):
    message = outcome(tiny, overlay_of(path, outside))
    assert message is not None, "accepted"
    assert named(message, path), message
    assert outcome(tiny, overlay_of(path, inside)) is None


def test_default_run_variant_is_checked_with_its_settings(tiny):
    variants = [{"name": "slow", "default_run": True, "set": {"duration_s": 2e-4}}]
    message = outcome(tiny, {"ablation": {"variants": variants}})
    assert "config key 'ablation.variants[0].set' (variant 'slow')" in message
    assert "experiment.virtual.duration_s" in message
    variants[0]["default_run"] = False  # only `snakemake ablation` runs it
    assert outcome(tiny, {"ablation": {"variants": variants}}) is None


def test_variant_config_applies_the_overrides(tiny):
    config = copy.deepcopy(tiny)
    validate(config, str(SCHEMA))
    derived = variant_config(config, {"striker_radius_m": 0.013, "noise_N": 0.0, "tolerance": None})
    assert derived["setup"]["striker_radius_m"] == 0.013
    assert derived["experiment"]["virtual"]["noise_N"] == 0.0
    assert derived["experiment"]["tolerance"] == config["experiment"]["tolerance"]
    assert derived["ablation"]["variants"] == [] and config["ablation"]["variants"]


def test_table_is_generated_from_schema_and_rules():
    schema = yaml.safe_load(SCHEMA.read_text())
    table = bounds_table(schema)
    assert (ROOT / "docs" / "config_bounds.md").read_text() == table, (
        "regenerate: python -m chain.pipeline.config_bounds "
        "workflow/schemas/config.schema.yaml > docs/config_bounds.md"
    )
    keys = {line.split("`")[1] for line in table.splitlines() if line.startswith("| `")}
    assert set(RULES) <= keys, sorted(set(RULES) - keys)


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
