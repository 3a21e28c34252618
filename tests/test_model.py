"""The chain model: particles and links of Eq. 1 with sensor beads, strikers and walls."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chain import (
    PCB_200B02_STIFFNESS,
    ParameterError,
    Striker,
    build_chain,
    contact_stiffness,
    launch_velocities,
    sphere_mass,
    uniform_chain,
)
from chain.physics.model import HERTZ, SPRING


def test_uniform_chain_is_eq1(bead_mass, kappa, tol):
    """N equal beads, N-1 equal Hertz contacts, free ends, no dissipation: Eq. 1."""
    model = uniform_chain(26)
    assert model.n_beads == model.n_particles == 26
    np.testing.assert_allclose(model.masses, bead_mass, rtol=tol.roundoff)
    assert np.all(model.link_kind == HERTZ)
    np.testing.assert_allclose(model.link_stiffness, kappa, rtol=tol.roundoff)
    assert np.all(model.wall_stiffness == 0) and np.all(model.link_eta == 0)
    np.testing.assert_array_equal(model.contact_link, np.arange(25))
    assert model.is_conservative
    assert not uniform_chain(26, eta=0.58e-6).is_conservative
    assert not uniform_chain(26, drag_rate=1.0).is_conservative


def test_sensor_bead_is_two_halves_and_a_spring(bead_mass, kappa, tol):
    """A sensor bead is two particles of m/2 joined by the PCB 200B02 spring; the bead's
    mass and its Hertz contacts are those of an unsplit bead."""
    model = uniform_chain(26, sensor_beads=[10, 17])
    assert model.n_beads == 26 and model.n_particles == 28
    np.testing.assert_allclose(model.bead_masses, bead_mass, rtol=tol.roundoff)
    assert model.masses.sum() == pytest.approx(26 * bead_mass, rel=tol.roundoff)
    assert model.sensor_beads == (10, 17)
    # The model's sensors are a set: any order gives the same chain.
    unordered = uniform_chain(26, sensor_beads=[17, 10])
    assert unordered.sensor_beads == (10, 17)
    np.testing.assert_array_equal(unordered.sensor_link, model.sensor_link)
    assert np.all(model.link_kind[model.sensor_link] == SPRING)
    np.testing.assert_allclose(model.link_stiffness[model.sensor_link], PCB_200B02_STIFFNESS)
    for link in model.sensor_link:
        assert model.masses[link] == model.masses[link + 1] == pytest.approx(bead_mass / 2)
    # The 25 contacts are all Hertz links with the bead-bead stiffness.
    assert np.all(model.link_kind[model.contact_link] == HERTZ)
    np.testing.assert_allclose(model.link_stiffness[model.contact_link], kappa, rtol=tol.roundoff)
    assert len(set(model.contact_link) | set(model.sensor_link)) == model.n_particles - 1


def test_strikers_are_extra_particles(steel, radius, tol):
    """A striker of radius 4 mm adds a particle of (4/3) pi Rs^3 rho with the Hertz
    stiffness of a 4 mm sphere against a 13 mm one."""
    model = uniform_chain(25, striker_radius=4e-3)
    assert model.n_beads == 25 and model.n_particles == 27
    assert (model.left_striker, model.right_striker) == (0, 26)
    striker_mass = sphere_mass(steel, 4e-3)
    striker_kappa = contact_stiffness(steel, 4e-3, steel, radius)
    for particle, link in ((0, 0), (26, 25)):
        assert model.masses[particle] == pytest.approx(striker_mass, rel=tol.roundoff)
        assert model.link_stiffness[link] == pytest.approx(striker_kappa, rel=tol.roundoff)
    left_only = uniform_chain(25, striker_radius=4e-3, strikers="left")
    assert (left_only.left_striker, left_only.right_striker) == (0, -1)
    assert Striker.sphere().mass == pytest.approx(striker_mass, rel=tol.roundoff)


def test_walls_use_the_flat_contact_stiffness(wall_kappa, tol):
    """A rigid wall is a Hertz contact of the end bead with a flat of the same steel."""
    model = uniform_chain(5, left_wall=True, right_wall=True)
    np.testing.assert_allclose(model.wall_stiffness, wall_kappa, rtol=tol.roundoff)


def test_build_chain_per_contact_values():
    """build_chain keeps any masses, stiffnesses and per-contact eta in bead order."""
    model = build_chain([1.0, 2.0, 3.0], [10.0, 20.0], eta=[0.0, 1e-6])
    np.testing.assert_array_equal(model.masses, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(model.link_stiffness, [10.0, 20.0])
    np.testing.assert_array_equal(model.link_eta, [0.0, 1e-6])


def test_launch_velocities_collision_and_reference(tol):
    """+V0 on bead 1, -V0 on bead N (both halves of a sensor end bead; the striker when
    there is one); a collision has zero total momentum."""
    model = uniform_chain(6, sensor_beads=[1])
    velocity = launch_velocities(model, [0.1, 0.2], [0.1, 0.0])
    assert velocity.shape == (2, model.n_particles)
    np.testing.assert_array_equal(velocity[0], [0.1, 0.1, 0, 0, 0, 0, -0.1])
    np.testing.assert_array_equal(velocity[1], [0.2, 0.2, 0, 0, 0, 0, 0.0])
    assert abs(velocity[0] @ model.masses) <= tol.roundoff * model.masses.sum() * 0.1
    with_strikers = uniform_chain(6, striker_radius=4e-3)
    velocity = launch_velocities(with_strikers, 0.5, 0.5)[0]
    assert velocity[0] == 0.5 and velocity[-1] == -0.5 and np.all(velocity[1:-1] == 0)


def test_bead_index_is_one_based():
    """Beads are numbered 1..N as in the paper."""
    model = uniform_chain(4)
    assert model.bead_index(1) == 0 and model.bead_index(4) == 3
    for bad in (0, 5, 1.5):
        with pytest.raises(ParameterError, match="bead"):
            model.bead_index(bad)


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: uniform_chain(1), "n_beads"),
        (lambda: uniform_chain(0), "n_beads"),
        (lambda: uniform_chain(2.5), "n_beads"),
        (lambda: build_chain([1.0], []), "bead_masses"),
        (lambda: build_chain([1.0, -1.0], [1.0]), r"bead_masses\[bead 2\]"),
        (lambda: build_chain([1.0, 1.0], [1.0, 1.0]), "contact_stiffnesses"),
        (lambda: build_chain([1.0, 1.0, 1.0], [1.0, 0.0]), r"contact_stiffnesses\[contact 2\]"),
        (lambda: uniform_chain(26, sensor_beads=[0]), "sensor_beads: bead 0 is outside"),
        (lambda: uniform_chain(26, sensor_beads=[27]), r"sensor_beads: bead 27 .* 1\.\.26"),
        (lambda: uniform_chain(26, sensor_beads=[10, 10]), "sensor_beads: duplicate bead"),
        (lambda: uniform_chain(26, sensor_beads=[10.5]), "sensor_beads: .* must be integers"),
        (lambda: uniform_chain(26, sensor_beads=[10], sensor_stiffness=0.0), "sensor_stiffness"),
        (lambda: uniform_chain(26, eta=-1e-6), "eta"),
        (lambda: build_chain([1.0, 1.0, 1.0], [1.0, 1.0], eta=[0.0, -1.0]), "eta"),
        (lambda: uniform_chain(26, drag_rate=-1.0), "drag_rate"),
        (lambda: uniform_chain(26, radius=0.0), "radius"),
        (lambda: uniform_chain(26, striker_radius=4e-3, strikers="middle"), "strikers"),
        (lambda: uniform_chain(26, striker_radius=-4e-3), "radius"),
        (lambda: uniform_chain(26, left_wall=True, striker_radius=4e-3), "left_striker"),
        (lambda: uniform_chain(26, right_wall=True, striker_radius=4e-3), "right_striker"),
        (lambda: build_chain([1.0, 1.0], [1.0], left_wall_stiffness=-1.0), "left_wall_stiffness"),
        (lambda: build_chain([1.0, 1.0], [1.0], right_wall_stiffness=math.nan), "right_wall"),
        (lambda: Striker(mass=0.0, contact_stiffness=1.0), "striker mass"),
        (lambda: Striker(mass=1.0, contact_stiffness=-1.0), "striker contact_stiffness"),
        (lambda: launch_velocities(uniform_chain(3), -0.1), "v_left"),
        (lambda: launch_velocities(uniform_chain(3), 0.1, -0.1), "v_right"),
        (lambda: launch_velocities(uniform_chain(3), math.nan), "v_left"),
    ],
)
def test_model_rejects_invalid_input(call, parameter):
    """Every invalid chain parameter raises ParameterError naming the parameter."""
    with pytest.raises(ParameterError, match=parameter):
        call()
