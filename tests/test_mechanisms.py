"""The mechanism study: the virtual experiment's candidate ingredients (bead
radius dispersion, gaps at rest, an off-centre collision), and the table and verdict
that compare each with its reference."""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from snakemake.utils import validate

from chain.apparatus.virtual import VirtualExperiment, plan_shots
from chain.apparatus.virtual_shots import apparatus_chain, chain_draws, rest_displacement
from chain.errors import ParameterError
from chain.physics.builders import uniform_chain
from chain.physics.materials import STEEL_100C6, contact_stiffness, sphere_mass
from chain.physics.simulation import simulate
from chain.report.numbers.mechanisms import candidate_sentence, friction_sentence
from chain.studies.mechanism_settings import candidate_variants, setting_name, sweep_settings
from chain.studies.mechanism_table import mechanism_rows

ROOT = Path(__file__).resolve().parents[1]

TINY = VirtualExperiment(
    n_beads=10,
    sensor_beads=(3, 8),
    impact_speeds_m_s=(1.0,),
    collision_shots=1,
    reference_shots=1,
    duration_s=0.5e-3,
    seed=5,
)


def test_without_candidates_the_chain_is_the_uniform_one():
    radii, gaps = chain_draws(TINY)
    assert np.all(radii == TINY.radius) and np.all(gaps == 0.0)
    model = apparatus_chain(TINY, "both", radii)
    plain = uniform_chain(
        10, radius=TINY.radius, eta=TINY.eta_s, sensor_beads=(3, 8), striker_radius=4e-3
    )
    np.testing.assert_array_equal(model.masses, plain.masses)
    np.testing.assert_array_equal(model.link_stiffness, plain.link_stiffness)


def test_dispersed_beads_carry_their_own_mass_and_contact_stiffness():
    settings = dataclasses.replace(TINY, radius_dispersion=1e-3, readout="felt")
    radii, _ = chain_draws(settings)
    assert 0 < np.std(radii / TINY.radius - 1) < 5e-3
    model = apparatus_chain(settings, "both", radii)
    np.testing.assert_allclose(model.bead_masses, [sphere_mass(STEEL_100C6, r) for r in radii])
    kappa = [
        contact_stiffness(STEEL_100C6, a, STEEL_100C6, b) for a, b in itertools.pairwise(radii)
    ]
    np.testing.assert_allclose(model.link_stiffness[model.contact_link], kappa)
    # The same seed gives the same beads; the shot plan does not move.
    np.testing.assert_array_equal(chain_draws(settings)[0], radii)
    pd.testing.assert_frame_equal(plan_shots(settings), plan_shots(TINY))


def test_a_gap_delays_the_first_contact_by_gap_over_speed():
    """Closed form: bead 1 launched at V towards bead 2 a gap g away touches it at g / V."""
    gap, speed = 2e-6, 0.1
    model = uniform_chain(4)
    shift = rest_displacement(model, np.array([gap, 0.0, 0.0]))
    np.testing.assert_allclose(shift, [0.0, gap, gap, gap])
    result = simulate(
        model, speed, 0.0, duration=1e-4, dt=1e-8, record_interval=1e-8, initial_displacement=shift
    )
    first = result.time[np.flatnonzero(result.contact_force[0, :, 0] > 0)[0]]
    assert first == pytest.approx(gap / speed, abs=1.01e-8)


def test_off_centre_settings_shift_the_right_launch_only():
    exact = dataclasses.replace(TINY, speed_mismatch=0.0, timing_jitter_s=0.0)
    moved = dataclasses.replace(exact, right_speed_offset=0.05, right_delay_s=2e-5)
    a, b = plan_shots(exact), plan_shots(moved)
    collision = b["kind"] == "collision"
    np.testing.assert_allclose(b["v_left_m_s"], a["v_left_m_s"])
    np.testing.assert_allclose(
        b.loc[collision, "v_right_m_s"], 1.05 * a.loc[collision, "v_right_m_s"]
    )
    np.testing.assert_allclose(b.loc[collision, "delay_s"], 2e-5)
    assert (b.loc[~collision, "delay_s"] == 0).all()


@pytest.mark.parametrize(
    "change",
    [
        {"radius_dispersion": -1e-3},
        {"radius_dispersion": 0.2},
        {"gap_mean_m": -1e-6},
        {"right_speed_offset": 0.7},
        {"right_delay_s": -1e-6},
    ],
)
def test_bad_candidate_settings_are_named(change):
    (name,) = change
    with pytest.raises(ParameterError, match=name):
        dataclasses.replace(TINY, **change)


def test_sweep_always_starts_from_the_frictionless_setting():
    config = yaml.safe_load((ROOT / "config.yaml").read_text())
    config["lammps"] = {"sweep": {"default_settings": [[0.3, 0.1]]}}
    validate(config, str(ROOT / "workflow" / "schemas" / "config.schema.yaml"))
    assert list(sweep_settings(config, full=False)) == ["mut000-mub000", "mut030-mub010"]
    full = sweep_settings(config, full=True)
    assert len(full) == 12 and next(iter(full)) == setting_name(0, 0)


def test_candidates_need_their_reference():
    variants = [
        {"name": "gaps", "mechanism": "gaps", "default_run": True, "set": {"gap_mean_m": 1e-7}},
        {"name": "other", "mechanism": "", "default_run": True, "set": {}},
    ]
    assert candidate_variants(variants, full=True) == {}
    reference = {"name": "mechanism_reference", "mechanism": "", "default_run": True, "set": {}}
    chosen = candidate_variants([reference, *variants], full=False)
    assert list(chosen) == ["mechanism_reference", "gaps"]
    assert chosen["gaps"] == ("gaps", "gap_mean_m=1e-07")


def _fits(slopes: dict, c: dict):
    """Synthetic delay and SSW fits: {(model, N): value}."""
    delays = pd.DataFrame(
        [{"model": m, "N": n, "C_us_N16": v, "C_stderr_us_N16": 0.1} for (m, n), v in c.items()]
    )
    ssw = pd.DataFrame(
        [{"model": m, "N": n, "slope": v, "slope_stderr": 0.002} for (m, n), v in slopes.items()]
    )
    return delays, ssw


def test_rows_divide_by_the_reference_of_the_same_chain():
    slopes = {("off", 25): 0.01, ("off", 26): 0.03, ("on", 25): 0.025, ("on", 26): 0.03}
    delays, ssw = _fits(slopes, {key: 44.0 for key in slopes})
    table = mechanism_rows("friction", {"off": "0", "on": "1"}, [delays], [ssw], "off")
    ratio = table.set_index(["setting", "N"])["ratio_to_frictionless"]
    assert ratio[("1", 25)] == pytest.approx(2.5) and ratio[("1", 26)] == pytest.approx(1.0)
    assert ratio[("0", 25)] == 1.0
    sentence = friction_sentence(table, "friction")
    assert "does not reach" not in sentence and "reaches" in sentence


def test_verdict_names_the_closest_candidate_and_its_contrast():
    slopes = {("ref", 25): 0.02, ("ref", 26): 0.04, ("a", 25): 0.02, ("a", 26): 0.06}
    slopes |= {("b", 25): 0.03, ("b", 26): 0.04}
    delays, ssw = _fits(slopes, {key: 44.0 for key in slopes})
    table = pd.concat(
        [
            mechanism_rows("reference", {"ref": "as configured"}, [delays], [ssw], "ref"),
            mechanism_rows("A", {"a": "x"}, [delays], [ssw], "ref"),
            mechanism_rows("B", {"b": "y"}, [delays], [ssw], "ref"),
        ]
    )
    # A: 1 and 1.5 times the reference, B: 1.5 and 1; A at 2 for N = 26 is the closest.
    table.loc[(table["mechanism"] == "A") & (table["N"] == 26), "ratio_to_frictionless"] = 2.0
    sentence = candidate_sentence(table, "friction", "reference")
    assert sentence.startswith("Of the other candidates at a plausible setting, A (x)")
    assert "2.00 -> 3.00" in sentence
    assert math.isfinite(table["C"].sum())


def test_verdict_does_not_judge_without_values():
    slopes = {("off", 25): math.nan, ("on", 25): math.nan}
    delays, ssw = _fits(slopes, {key: 44.0 for key in slopes})
    table = mechanism_rows("friction", {"off": "0", "on": "1"}, [delays], [ssw], "off")
    assert "cannot be judged" in friction_sentence(table, "friction")
