"""The pipeline's config: the JSON schema (workflow/schemas/config.schema.yaml), the
semantic checks of chain.config_checks, and the shipped configs (config.yaml, whatif/).

A bad config must stop before any job runs, with a message naming the key.
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

from chain.config_checks import ConfigError, check_config, key_name
from chain.materials import MATERIALS
from chain.pulses import ESTIMATORS

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
OVERLAYS = sorted((ROOT / "whatif").glob("*.yaml")) + sorted(
    (ROOT / "tests" / "configs").glob("*.yaml")
)


def load(path: Path) -> dict:
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


# ---- the schema rejects bad configs, naming the key ---------------------------------


@pytest.mark.parametrize(
    ("change", "where", "what"),
    [
        (lambda c: c.update(radius_m=-0.013), instance("radius_m"), "minimum"),
        (lambda c: c.update(radius="0.013"), instance(), "'radius' was unexpected"),
        (lambda c: c.update(material="granite"), instance("material"), "granite"),
        (lambda c: c["chains"][1].update(N="26"), instance("chains", 1, "N"), "integer"),
        (lambda c: c["chains"][0].update(sensors=[9]), instance("chains", 0, "sensors"), "short"),
        (
            lambda c: c["models"][1].pop("eta_s"),
            instance("models", 1),
            "'eta_s' is a required property",
        ),
        (lambda c: c["launch"].update(count=0), instance("launch", "count"), "minimum"),
        (
            lambda c: c.update(simulation={"duration_s": "long"}),
            instance("simulation", "duration_s"),
            "number",
        ),
        (
            lambda c: c.update(analysis={"estimators": ["fit_full", "median"]}),
            instance("analysis", "estimators", 1),
            "median",
        ),
        (lambda c: c.update(run_name="my run/1"), instance("run_name"), "does not match"),
        (
            lambda c: c.update(figures={"parity_ssw_vs_N": "yes"}),
            instance("figures", "parity_ssw_vs_N"),
            "boolean",
        ),
    ],
)
def test_schema_rejects_with_key_named(paper, change, where, what):
    config = copy.deepcopy(paper)
    change(config)
    message = schema_error(config)
    assert f"On {where}:" in message
    assert what in message


# ---- semantic checks -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (lambda c: c["chains"][0].update(sensors=[9, 30]), "chains[0].sensors[1]"),
        (lambda c: c["chains"][1].update(sensors=[17, 10]), "chains[1].sensors"),
        (lambda c: c["chains"][1].update(N=25), "chains[1].N"),
        (lambda c: c["models"][1].update(name="elastic"), "models[1].name"),
        (lambda c: c["launch"].update(v0_min_m_s=2.0), "launch.v0_min_m_s"),
        (lambda c: c["simulation"].update(time_step_s=1e-5), "simulation.time_step_s"),
        (lambda c: c["analysis"].update(estimators=["peak"]), "analysis.main_estimator"),
        (lambda c: c["figures"].update(traces_model="plastic"), "figures.traces_model"),
        (lambda c: c["figures"].update(traces_N=[25, 27]), "figures.traces_N[1]"),
        (lambda c: c["figures"].update(representative_index=12), "figures.representative_index"),
    ],
)
def test_semantic_checks_name_the_key(paper, change, key):
    config = validated(paper)
    change(config)
    with pytest.raises(ConfigError) as error:
        check_config(config)
    assert str(error.value).startswith(f"config key '{key}'")


def test_key_name():
    assert key_name(["chains", 0, "sensors", 1]) == "chains[0].sensors[1]"
    assert key_name([]) == "<top level>"


@pytest.mark.parametrize(
    ("overlay", "key"),
    [
        ("run_name: bad\nchains:\n  - {N: 25, sensors: [9, 40]}\n", "chains[0].sensors[1]"),
        ("run_name: bad\nradius_m: -1\n", "instance['radius_m']"),
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
