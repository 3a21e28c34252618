"""Closed forms of the paper: Hertz collision, Nesterenko's wave (Eq. 4-5), C_bal (Eq. 6)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from chain import ParameterError
from chain.physics.theory import (
    HERTZ_TIME_CONSTANT,
    PAPER_TIME_CONSTANT,
    ballistic_delay,
    ballistic_delay_constant_exact,
    ballistic_delay_constant_paper,
    ballistic_delay_constant_paper_first_line,
    bead_velocity_from_force,
    cos6_pulse,
    force_from_bead_velocity,
    hertz_contact_time,
    hertz_max_overlap,
    hertz_peak_force,
    nesterenko_speed_from_force,
    nesterenko_speed_from_velocity,
    pulse_half_width,
    solitary_wave_length,
)

US = 1e-6  # s per microsecond
FORCES = np.geomspace(1.0, 5000.0, 13)  # N, the paper's range and beyond


def test_hertz_time_constant_is_the_quadrature(tol):
    """HERTZ_TIME_CONSTANT = 2 int_0^1 dx / sqrt(1 - x^(5/2)) (numerical quadrature)."""

    # Factor out the integrable (1 - x)^(-1/2) end singularity; the rest is smooth.
    def smooth(x):
        return math.sqrt((1.0 - x) / (1.0 - x**2.5)) if x < 1.0 else math.sqrt(0.4)

    value, _ = quad(smooth, 0.0, 1.0, weight="alg", wvar=(0.0, -0.5), epsabs=0, epsrel=1e-13)
    assert 2.0 * value == pytest.approx(HERTZ_TIME_CONSTANT, rel=tol.quadrature)
    assert round(HERTZ_TIME_CONSTANT, 2) == PAPER_TIME_CONSTANT  # Landau & Lifshitz's 2.94


def test_hertz_time_constant_is_the_gamma_ratio():
    """The written-out constant is 2 sqrt(pi) Gamma(7/5) / Gamma(9/10) to the last bit,
    with scipy's Gamma (the value every table was computed with)."""
    from scipy.special import gamma

    assert HERTZ_TIME_CONSTANT == 2.0 * math.sqrt(math.pi) * gamma(1.4) / gamma(0.9)


def test_paper_ballistic_constant_is_4974(steel, radius, tol):
    """Eq. 6 as printed gives C_bal = 49.74 us N^(1/6) for 100C6 beads of R = 13 mm."""
    value_us = ballistic_delay_constant_paper(steel, radius) / US
    assert value_us == pytest.approx(49.74, abs=tol.cbal_paper_abs_us)


def test_eq6_first_line_matches_printed_prefactor(steel, radius, tol):
    """The first line of Eq. 6 (2.94, mu = m, V_m(F_m) from Eq. 5) equals the second (0.7612)."""
    first = ballistic_delay_constant_paper_first_line(steel, radius)
    assert first == pytest.approx(
        ballistic_delay_constant_paper(steel, radius), rel=tol.cbal_first_line
    )


def test_exact_over_paper_ballistic_constant(steel, radius, tol):
    """C_bal exact / C_bal paper = 2^(-2/5) * 2.9432 / 2.94 (reduced mass m/2, exact constant)."""
    ratio = 2.0 ** (-0.4) * HERTZ_TIME_CONSTANT / PAPER_TIME_CONSTANT
    exact = ballistic_delay_constant_exact(steel, radius)
    assert exact / ballistic_delay_constant_paper_first_line(steel, radius) == pytest.approx(
        ratio, rel=tol.roundoff
    )
    assert exact / ballistic_delay_constant_paper(steel, radius) == pytest.approx(
        ratio, rel=tol.cbal_first_line
    )


def test_ballistic_delay_is_constant_times_force_power(steel, radius, tol):
    """Delta = C F_m^(-1/6): a factor 64 in force shortens the delay by exactly 2."""
    constant = ballistic_delay_constant_paper(steel, radius)
    delays = ballistic_delay(np.array([1.0, 64.0]), constant)
    assert delays[0] == pytest.approx(constant, rel=tol.roundoff)
    assert delays[0] / delays[1] == pytest.approx(2.0, rel=tol.roundoff)


def test_hertz_collision_energy_balance(bead_mass, kappa, tol):
    """At the largest overlap all kinetic energy of relative motion is Hertz energy:
    (2/5) kappa delta_max^(5/2) = (1/2) mu v^2, and F_peak = kappa delta_max^(3/2)."""
    for speed in (0.01, 0.1, 1.0):
        mu = bead_mass / 2.0
        delta = hertz_max_overlap(bead_mass, bead_mass, kappa, speed)
        assert 0.4 * kappa * delta**2.5 == pytest.approx(0.5 * mu * speed**2, rel=tol.roundoff)
        peak = hertz_peak_force(bead_mass, bead_mass, kappa, speed)
        assert peak == pytest.approx(kappa * delta**1.5, rel=tol.roundoff)


def test_hertz_contact_time_scaling(bead_mass, kappa, wall_kappa, tol):
    """t_c = 2.9432 (5 mu / 4 kappa)^(2/5) v^(-1/5): v^(-1/5), mu^(2/5), kappa^(-2/5)."""
    base = hertz_contact_time(bead_mass, bead_mass, kappa, 0.1)
    expected = HERTZ_TIME_CONSTANT * (5 * bead_mass / 2 / (4 * kappa)) ** 0.4 * 0.1**-0.2
    assert base == pytest.approx(expected, rel=tol.roundoff)
    assert hertz_contact_time(bead_mass, bead_mass, kappa, 3.2) == pytest.approx(
        base * 32.0**-0.2, rel=tol.roundoff
    )
    # A bead against an immovable body has mu = m (twice the two-bead reduced mass).
    assert hertz_contact_time(bead_mass, math.inf, kappa, 0.1) == pytest.approx(
        base * 2.0**0.4, rel=tol.roundoff
    )
    assert hertz_contact_time(bead_mass, bead_mass, 2 * kappa, 0.1) == pytest.approx(
        base * 2.0**-0.4, rel=tol.roundoff
    )
    # Order of magnitude: two of the paper's beads at 0.1 m/s touch for ~100 us.
    assert 50e-6 < base < 200e-6
    assert hertz_contact_time(bead_mass, math.inf, wall_kappa, 0.1) > 0


def test_force_and_bead_velocity_are_inverse(steel, radius, tol):
    """force_from_bead_velocity inverts bead_velocity_from_force (Eq. 5, both forms)."""
    velocities = bead_velocity_from_force(FORCES, steel, radius)
    assert np.all(np.diff(velocities) > 0)
    back = force_from_bead_velocity(velocities, steel, radius)
    np.testing.assert_allclose(back, FORCES, rtol=tol.roundoff)
    scalar = bead_velocity_from_force(100.0, steel, radius)
    assert isinstance(scalar, float)
    assert force_from_bead_velocity(scalar, steel, radius) == pytest.approx(100.0, rel=tol.roundoff)


def test_eq5_two_forms_agree(steel, radius, tol):
    """Eq. 5: v(F_m) = v(V_m) when V_m = bead_velocity_from_force(F_m)."""
    from_force = nesterenko_speed_from_force(FORCES, steel, radius)
    from_velocity = nesterenko_speed_from_velocity(
        bead_velocity_from_force(FORCES, steel, radius), steel
    )
    np.testing.assert_allclose(from_velocity, from_force, rtol=tol.roundoff)


def test_nesterenko_speed_scaling_and_magnitude(steel, radius, tol):
    """v ~ F_m^(1/6) (Eq. 5); a 100 N wave in the paper's chain runs at ~450 m/s."""
    speeds = nesterenko_speed_from_force(np.array([1.0, 64.0]), steel, radius)
    assert speeds[1] / speeds[0] == pytest.approx(2.0, rel=tol.roundoff)
    assert 400.0 < nesterenko_speed_from_force(100.0, steel, radius) < 550.0


def test_pulse_width_and_wave_length(steel, radius, tol):
    """Eq. 4: the hump spans pi R sqrt(10) ~ 4.97 bead diameters; tau = R sqrt(10) / v."""
    assert solitary_wave_length(radius) / (2 * radius) == pytest.approx(
        math.pi * math.sqrt(10) / 2, rel=tol.roundoff
    )
    assert solitary_wave_length(radius) / (2 * radius) == pytest.approx(4.967, abs=1e-3)
    tau = pulse_half_width(100.0, steel, radius)
    speed = nesterenko_speed_from_force(100.0, steel, radius)
    assert tau * speed == pytest.approx(radius * math.sqrt(10), rel=tol.roundoff)


def test_cos6_pulse_shape(tol):
    """F_m cos^6((t - T)/tau) on one hump: peak F_m at T, zero outside, area 5 pi tau F_m / 16."""
    peak, arrival, tau = 120.0, 300e-6, 25e-6
    time = np.linspace(0.0, 600e-6, 600_001)
    pulse = cos6_pulse(time, peak, arrival, tau)
    assert pulse.max() == pytest.approx(peak, rel=tol.roundoff)
    assert time[np.argmax(pulse)] == pytest.approx(arrival, abs=1e-12)
    assert np.all(pulse[np.abs(time - arrival) >= math.pi * tau / 2] == 0.0)
    area = pulse.sum() * (time[1] - time[0])  # the pulse vanishes at both ends
    assert area == pytest.approx(5 * math.pi / 16 * tau * peak, rel=1e-8)


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda: hertz_contact_time(0.07, 0.07, 1e10, 0.0), "relative_speed"),
        (lambda: hertz_contact_time(0.07, 0.07, 1e10, -0.1), "relative_speed"),
        (lambda: hertz_contact_time(0.07, 0.07, 0.0, 0.1), "kappa"),
        (lambda: hertz_contact_time(-0.07, 0.07, 1e10, 0.1), "mass_a"),
        (lambda: hertz_peak_force(0.07, 0.0, 1e10, 0.1), "mass_b"),
        (lambda: solitary_wave_length(0.0), "radius"),
    ],
)
def test_theory_rejects_bad_parameters(call, parameter):
    """Non-positive physical parameters are rejected by name."""
    with pytest.raises(ParameterError, match=parameter):
        call()


def test_two_walls_is_not_a_collision():
    """Two infinite masses have no reduced mass."""
    with pytest.raises(ValueError, match="infinite"):
        hertz_contact_time(math.inf, math.inf, 1e10, 0.1)
