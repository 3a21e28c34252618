"""Bad configs: every one stopped by the checks the Snakefile runs before any
job, with a message naming the key, and nothing written under results/.

The checks are run as the Snakefile runs them (config files as text, the JSON schema,
chain.pipeline.config.check.check_config, experiment_parts, the dataset check), in a
temporary working directory, so that "nothing written" is observable; a few cases go
through Snakemake itself (test_bad_input_workflow.py).
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest
import yaml
from snakemake.exceptions import WorkflowError
from snakemake.utils import update_config, validate

from chain.errors import ConfigError
from chain.pipeline.config.check import check_config, check_finite
from chain.pipeline.config.files import check_config_file
from chain.pipeline.plan.datasets import check_experiment_datasets, experiment_parts

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
NAN, INF = math.nan, math.inf


@pytest.fixture(scope="module")
def paper() -> dict:
    return yaml.safe_load((ROOT / "config.yaml").read_text())


def stop_message(config: dict, root: Path) -> str:
    """What stops ``config`` (schema, then the library's checks, as the Snakefile runs
    them with ``root`` as working directory); fails the test if it passes."""
    config = copy.deepcopy(config)
    try:
        validate(config, str(SCHEMA))
        check_config(config)
        parts = experiment_parts(config, root=root)
        check_experiment_datasets(config, parts, root=root, cache_dir=None)
    except (WorkflowError, ConfigError) as error:
        return str(error)
    pytest.fail("the config was accepted")


def named(message: str, path: tuple) -> bool:
    """Whether ``message`` names the key ``path`` as the checks do (dotted or as
    jsonschema's instance['a'][0]['b'])."""
    dotted = ""
    for part in path:
        dotted += f"[{part}]" if isinstance(part, int) else (f".{part}" if dotted else part)
    instance = "instance" + "".join(f"[{p!r}]" for p in path)
    return f"'{dotted}'" in message or instance in message


def apply(paper: dict, path: tuple, value) -> dict:
    config = copy.deepcopy(paper)
    node = config
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return config


# (key path, bad value): NaN and infinities in every kind of numeric key, and a few
# other values the schema or the checks refuse.
BAD_CONFIGS = [
    (("radius_m",), NAN),
    (("radius_m",), INF),
    (("chains", 0, "N"), NAN),
    (("chains", 1, "sensors", 0), INF),
    (("models", 1, "eta_s"), NAN),
    (("models", 0, "eta_s"), -INF),
    (("launch", "v0_min_m_s"), NAN),
    (("launch", "v0_max_m_s"), NAN),
    (("launch", "v0_max_m_s"), INF),
    (("launch", "count"), NAN),
    (("simulation", "duration_s"), NAN),
    (("simulation", "time_step_s"), NAN),
    (("simulation", "record_interval_s"), INF),
    (("simulation", "max_energy_drift"), NAN),
    (("simulation", "max_energy_drift"), INF),
    (("setup", "striker_radius_m"), NAN),
    (("figures", "representative_force_N"), NAN),
    (("figures", "representative_force_N"), INF),
    (("figures", "experiment_force_N"), NAN),
    (("experiment", "tolerance"), NAN),
    (("experiment", "virtual", "eta_s"), NAN),
    (("experiment", "virtual", "drag_rate_per_s"), INF),
    (("experiment", "virtual", "sensor_stiffness_N_per_m"), NAN),
    (("experiment", "virtual", "sensitivity_mV_per_N"), INF),
    (("experiment", "virtual", "impact_speeds_m_s", 2), NAN),
    (("experiment", "virtual", "speed_mismatch"), NAN),
    (("experiment", "virtual", "timing_jitter_s"), INF),
    (("experiment", "virtual", "noise_N"), NAN),
    (("experiment", "virtual", "sampling_interval_s"), NAN),
    (("experiment", "virtual", "adc_range_V"), INF),
    (("experiment", "virtual", "duration_s"), NAN),
    (("experiment", "virtual", "time_step_s"), NAN),
    (("experiment", "bad_channels"), "ignore"),
    (("experiment", "source"), "lab"),
    (("launch", "v0_min_m_s"), "fast"),
    (("studies", "ablation"), "yes"),
    (("studies", "mechanisms"), 1),
    (("studies", "c_sensitivity"), None),
    # Shorter than 26 beads, an elastic chain's SSW never separates from the main wave.
    (("long_chains", "N", 0), 3),
    (("long_chains", "N", 1), 25),
]


@pytest.mark.parametrize(
    ("path", "value"), BAD_CONFIGS, ids=[f"{'.'.join(map(str, p))}={v}" for p, v in BAD_CONFIGS]
)
def test_bad_config_is_stopped_naming_the_key(paper, tmp_path, monkeypatch, path, value):
    monkeypatch.chdir(tmp_path)
    message = stop_message(apply(paper, path, value), tmp_path)
    assert named(message, path), message
    assert not (tmp_path / "results").exists()


@pytest.mark.parametrize("study", ["lammps", "mechanism_study"])
def test_unknown_study_is_stopped_naming_it(paper, tmp_path, monkeypatch, study):
    """A study the run does not know (a typo, the retired top-level key's name) stops
    the run, naming the ``studies`` key and the unknown name."""
    monkeypatch.chdir(tmp_path)
    message = stop_message(apply(paper, ("studies", study), True), tmp_path)
    assert f"'{study}' was unexpected" in message and named(message, ("studies",)), message
    assert not (tmp_path / "results").exists()


def test_the_retired_mechanism_study_key_is_stopped(paper, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    message = stop_message({**paper, "mechanism_study": False}, tmp_path)
    assert "'mechanism_study' was unexpected" in message, message


def test_every_non_finite_key_is_listed_at_once(paper):
    config = apply(apply(paper, ("radius_m",), NAN), ("launch", "v0_min_m_s"), INF)
    with pytest.raises(ConfigError) as error:
        check_finite(config)
    lines = str(error.value).splitlines()
    assert len(lines) == 2
    assert named(lines[0], ("radius_m",)) and named(lines[1], ("launch", "v0_min_m_s"))


BAD_DATASET_CONFIGS = [
    ({"source": "measured", "datasets": ["data/nowhere"]}, ("experiment", "datasets", 0)),
    ({"source": "measured", "datasets": []}, ("experiment", "datasets")),
    ({"source": "virtual", "datasets": ["tests/data/virtual_small"]}, ("experiment", "datasets")),
]


@pytest.mark.parametrize(("experiment", "path"), BAD_DATASET_CONFIGS)
def test_bad_dataset_keys_are_named(paper, tmp_path, monkeypatch, experiment, path):
    monkeypatch.chdir(tmp_path)
    config = copy.deepcopy(paper)
    update_config(config, {"experiment": experiment})
    assert named(stop_message(config, tmp_path), path)
    assert not (tmp_path / "results").exists()


# ---- config files as text --------------------------------------------------------------

BAD_FILES = [
    ("launch:\n  v0_min_m_s: 0.1\n   count: [1\n", 3, "not valid YAML"),
    ("run_name: x\nlaunch: {v0_min_m_s: 0.1\n", 3, "not valid YAML"),
    ("run_name: x\n\trun_name: y\n", 2, "not valid YAML"),
    ("run_name: a\nseed: 1\nrun_name: b\n", 3, "'run_name' is given twice (lines 1 and 3)"),
    ("launch:\n  count: 3\n  count: 4\n", 3, "'count' is given twice"),
]


@pytest.mark.parametrize(("text", "line", "fragment"), BAD_FILES)
def test_config_file_mistakes_name_file_and_line(tmp_path, text, line, fragment):
    path = tmp_path / "whatif.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError) as error:
        check_config_file(path)
    message = str(error.value)
    assert message.startswith(f"{path} line {line}"), message
    assert fragment in message


def test_shipped_config_files_pass():
    for path in [ROOT / "config.yaml", *sorted((ROOT / "whatif").glob("*.yaml"))]:
        check_config_file(path)


def test_command_line_names_file_and_line(tmp_path, capsys):
    from chain.pipeline.config.files import main

    bad = tmp_path / "bad.yaml"
    bad.write_text("launch:\n  v0_min_m_s: 0.1\n   count: [1\n")
    assert main([str(ROOT / "config.yaml"), str(bad)]) == 1
    assert f"{bad} line 3" in capsys.readouterr().err
