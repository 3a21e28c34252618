"""The numba RK4 integrator: against an independent solver, walls, failure modes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from chain import (
    PCB_200B02_STIFFNESS,
    IntegrationError,
    ParameterError,
    contact_stiffness,
    default_time_step,
    integrate,
    launch_velocities,
    simulate,
    sphere_mass,
    uniform_chain,
)
from chain.physics.theory import hertz_contact_time, hertz_peak_force

#: The kernels these tests run, compiled in turns by the workers (conftest.py).
pytestmark = pytest.mark.usefixtures("unit_test_kernels")


class ReferenceChain:
    """A plain-numpy right-hand side of the same physics, written from the paper's
    equations without the library's model arrays: particles on a line, each neighbouring
    pair joined either by a Kuwabara-Kono Hertz contact,
    F = kappa delta^(3/2) + (3/2) eta kappa delta^(1/2) d(delta)/dt clipped at F >= 0
    (zero when delta <= 0), or by a linear spring F = k delta; optional rigid walls."""

    def __init__(self, masses, links, right_wall=None):
        self.masses = np.asarray(masses, dtype=float)
        # links: list of ("hertz", kappa, eta) or ("spring", k, 0)
        self.is_spring = np.array([kind == "spring" for kind, _, _ in links])
        self.stiffness = np.array([value for _, value, _ in links], dtype=float)
        self.eta = np.array([eta for _, _, eta in links], dtype=float)
        self.right_wall = right_wall  # (kappa, eta) or None

    @staticmethod
    def _hertz(kappa, eta, delta, rate):
        compressed = np.maximum(delta, 0.0)
        root = np.sqrt(compressed)
        force = kappa * compressed * root + 1.5 * eta * kappa * root * rate
        return np.where(delta > 0.0, np.maximum(force, 0.0), 0.0)

    def forces(self, y):
        """(link forces, right wall force) for a state y = (u, v) or a batch of states."""
        n = len(self.masses)
        u, v = y[:n], y[n:]
        delta = u[:-1] - u[1:]
        rate = v[:-1] - v[1:]
        stiffness = self.stiffness.reshape((-1,) + (1,) * (delta.ndim - 1))
        eta = self.eta.reshape(stiffness.shape)
        spring = self.is_spring.reshape(stiffness.shape)
        link = np.where(spring, stiffness * delta, self._hertz(stiffness, eta, delta, rate))
        wall = np.zeros_like(u[-1])
        if self.right_wall is not None:
            wall = self._hertz(self.right_wall[0], self.right_wall[1], u[-1], v[-1])
        return link, wall

    def rhs(self, _t, y):
        n = len(self.masses)
        link, wall = self.forces(y)
        force = np.zeros(n)
        force[:-1] -= link
        force[1:] += link
        force[-1] -= wall
        return np.concatenate([y[n:], force / self.masses])


def test_rk4_matches_dop853_reference(steel, radius, bead_mass, kappa, wall_kappa, eta, tol):
    """Same run, two solvers: the numba RK4 (default step) and scipy DOP853 (rtol 1e-12)
    on an independent numpy right-hand side agree on every link force to 1e-6 of the peak.

    N = 8 with a 4 mm striker on the left, bead 4 a split sensor bead, a rigid wall on
    the right and Kuwabara-Kono dissipation everywhere: every kind of link is exercised.
    """
    model = uniform_chain(
        8, eta=eta, sensor_beads=[4], striker_radius=4e-3, strikers="left", right_wall=True
    )
    striker_mass = sphere_mass(steel, 4e-3)
    striker_kappa = contact_stiffness(steel, 4e-3, steel, radius)
    masses = [striker_mass, bead_mass, bead_mass, bead_mass, bead_mass / 2, bead_mass / 2]
    masses += [bead_mass] * 4
    links = [("hertz", striker_kappa, eta)] + [("hertz", kappa, eta)] * 3
    links += [("spring", PCB_200B02_STIFFNESS, 0.0)] + [("hertz", kappa, eta)] * 4
    reference = ReferenceChain(masses, links, right_wall=(wall_kappa, eta))

    speed = 1.0
    dt = default_time_step(model, speed)
    raw = integrate(model, launch_velocities(model, speed), 700e-6, dt, record_every=50)
    y0 = np.zeros(2 * len(masses))
    y0[len(masses)] = speed
    solution = solve_ivp(
        reference.rhs,
        (0.0, raw.time[-1]),
        y0,
        method="DOP853",
        rtol=1e-12,
        atol=np.r_[np.full(len(masses), 1e-16), np.full(len(masses), 1e-13)],
        t_eval=raw.time,
    )
    assert solution.success
    link, wall = reference.forces(solution.y)
    scale = raw.link_force[0].max()
    np.testing.assert_allclose(raw.link_force[0], link.T, rtol=0, atol=tol.ivp_force * scale)
    assert wall.max() > 0.01 * scale  # the pulse reached the wall within the record
    np.testing.assert_allclose(raw.wall_force[0, :, 1], wall, rtol=0, atol=tol.ivp_force * scale)


def test_wall_bounce_is_elastic(bead_mass, wall_kappa, tol, release_time, peak_of):
    """A bead hitting a rigid wall with eta = 0 leaves with its speed reversed (to 1e-9),
    after the Hertz contact time of a bead against an immovable flat, with the Hertz peak
    force; the energy is conserved."""
    model = uniform_chain(2, left_wall=True)
    speed = 0.5
    contact_time = hertz_contact_time(bead_mass, math.inf, wall_kappa, speed)
    dt = contact_time / 2000
    # Bead 1 moves left into the wall; bead 2 is parked 1 m away and never takes part.
    raw = integrate(
        model,
        np.array([-speed, 0.0]),
        1.2 * contact_time,
        dt,
        initial_displacement=np.array([0.0, 1.0]),
    )
    assert raw.final_velocity[0, 0] == pytest.approx(speed, rel=tol.wall_speed)
    assert raw.final_velocity[0, 1] == 0.0
    assert raw.energy_drift[0] <= tol.energy_drift
    force = raw.wall_force[0, :, 0]
    assert release_time(raw.time, force) == pytest.approx(contact_time, rel=tol.hertz_collision)
    peak = hertz_peak_force(bead_mass, math.inf, wall_kappa, speed)
    assert peak_of(raw.time, force)[1] == pytest.approx(peak, rel=tol.hertz_collision)


def test_launches_in_a_batch_are_independent():
    """A launch gives bit-identical results alone or inside a batch (one thread per launch)."""
    model = uniform_chain(10, eta=0.58e-6)
    velocity = launch_velocities(model, [0.05, 0.3, 0.1], [0.05, 0.0, 0.1])
    dt = default_time_step(model, 0.3)
    batch = integrate(model, velocity, 200e-6, dt, record_every=20)
    alone = integrate(model, velocity[1], 200e-6, dt, record_every=20)
    np.testing.assert_array_equal(batch.link_force[1], alone.link_force[0])
    np.testing.assert_array_equal(batch.energy[1], alone.energy[0])


def test_too_large_a_step_raises_and_names_dt():
    """dt = 5 us at 1 m/s (contact time ~60 us / 2, 3000x the default) is refused with
    IntegrationError naming dt, never a silent NaN result."""
    with pytest.raises(IntegrationError, match=r"dt = 5\.000e-06 s"):
        simulate(uniform_chain(26), 1.0, 1.0, duration=2.6e-3, dt=5e-6)


def test_blow_up_is_reported_not_returned():
    """A step so large that the state overflows raises IntegrationError (non-finite state)."""
    model = uniform_chain(3)
    with pytest.raises(IntegrationError, match="dt"):
        integrate(model, np.array([1e3, 0.0, 0.0]), 1e-2, 1e-3, max_energy_drift=math.inf)


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [
        ({"duration": 0.0}, "duration"),
        ({"duration": -1e-3}, "duration"),
        ({"dt": 0.0}, "dt"),
        ({"dt": -1e-8}, "dt"),
        ({"record_every": 0}, "record_every"),
        ({"max_energy_drift": 0.0}, "max_energy_drift"),
        ({"initial_velocity": np.zeros(4)}, "initial_velocity"),
        ({"initial_velocity": np.array([np.nan, 0, 0])}, "initial_velocity"),
        ({"initial_displacement": np.zeros((2, 3))}, "initial_displacement"),
    ],
)
def test_integrate_rejects_invalid_input(kwargs, parameter):
    """integrate names the bad parameter before running anything."""
    arguments = {
        "initial_velocity": np.array([0.1, 0.0, 0.0]),
        "duration": 1e-4,
        "dt": 1e-8,
    }
    arguments.update(kwargs)
    with pytest.raises(ParameterError, match=parameter):
        integrate(uniform_chain(3), **arguments)
