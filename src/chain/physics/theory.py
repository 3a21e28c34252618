"""Closed forms of the paper: Nesterenko's solitary wave (Eq. 4-5), the Hertz
two-sphere collision, and the ballistic estimate of the crossing delay (Eq. 6).

SI units throughout; constants named ``*_us_N16`` are in microseconds N^(1/6).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from chain.errors import require_positive
from chain.physics.materials import Material, contact_stiffness, get_material, sphere_mass

#: Contact-time constant of a Hertz collision, t_c = HERTZ_TIME_CONSTANT * delta_max / v_rel:
#: 2 sqrt(pi) Gamma(7/5) / Gamma(9/10), rounded to 2.94 by Landau & Lifshitz and Eq. 6.
#: Written out as ``scipy.special.gamma`` evaluates it (tests/test_theory.py checks the
#: bits), so that importing the closed forms costs no scipy (about 0.3 s per job).
HERTZ_TIME_CONSTANT = 2.9432751843247043

#: The rounded constant printed in the paper's Eq. 6.
PAPER_TIME_CONSTANT = 2.94

#: The numerical prefactor printed in the second line of Eq. 6.
PAPER_CBAL_PREFACTOR = 0.7612

#: Contact time of two free beads over that of a bead against an immovable body, at the
#: same approach speed: t_c grows as (mass)^(2/5), and two free beads collide with the
#: reduced mass m/2 where Eq. 6 takes m.
REDUCED_MASS_TIME_FACTOR = 2.0 ** (-0.4)

#: The exact ballistic C over Eq. 6's (the reduced mass and the unrounded Hertz constant):
#: C_bal_exact / C_bal as printed, for any beads.
EXACT_OVER_PAPER_BALLISTIC = REDUCED_MASS_TIME_FACTOR * HERTZ_TIME_CONSTANT / PAPER_TIME_CONSTANT


#: V_m / V0 of the solitary wave formed when bead 1 of a free chain is launched at V0
#: (0.47 measured: F_m = 1030 N at 1 m/s in the paper's chains); a little lower, so that
#: the estimated wave is, if anything, too slow.
LAUNCH_VELOCITY_RATIO = 0.45


def hertz_max_overlap(mass_a: float, mass_b: float, kappa: float, relative_speed: float) -> float:
    """Largest overlap of a head-on Hertz collision, m.

    Energy conservation, (1/2) mu v^2 = (2/5) kappa delta_max^(5/2), gives
    delta_max = (5 mu v^2 / (4 kappa))^(2/5), with mu the reduced mass.

    Parameters
    ----------
    mass_a, mass_b : float
        Masses of the two bodies, kg (``math.inf`` for a fixed wall).
    kappa : float
        Contact stiffness, N/m^(3/2).
    relative_speed : float
        Approach speed before contact, m/s.
    """
    mu = _reduced_mass(mass_a, mass_b)
    kappa = require_positive("kappa", kappa)
    relative_speed = require_positive("relative_speed", relative_speed)
    return (5.0 * mu * relative_speed**2 / (4.0 * kappa)) ** 0.4


def hertz_contact_time(mass_a: float, mass_b: float, kappa: float, relative_speed: float) -> float:
    """Exact duration of a head-on elastic Hertz collision, s.

    From energy conservation the overlap obeys
    (d delta/dt)^2 = v^2 - (4 kappa / (5 mu)) delta^(5/2), so
    t_c = 2 int_0^delta_max d delta / sqrt(...) = 2.9432 delta_max / v
    = 2.9432 (5 mu / (4 kappa))^(2/5) v^(-1/5), with mu = m_a m_b / (m_a + m_b).
    Eq. 6 rounds the constant to 2.94 and takes mu = m (a bead against an immovable
    body) where two equal free beads have mu = m / 2: its time is 2^(2/5) times the exact one.

    Parameters as in :func:`hertz_max_overlap` (kg, kg, N/m^(3/2), m/s).
    """
    delta_max = hertz_max_overlap(mass_a, mass_b, kappa, relative_speed)
    return HERTZ_TIME_CONSTANT * delta_max / relative_speed


def hertz_peak_force(mass_a: float, mass_b: float, kappa: float, relative_speed: float) -> float:
    """Largest contact force of a head-on elastic Hertz collision, kappa delta_max^(3/2), N.
    Parameters as in :func:`hertz_max_overlap`."""
    return kappa * hertz_max_overlap(mass_a, mass_b, kappa, relative_speed) ** 1.5


def nesterenko_speed_from_force(
    peak_force: float | np.ndarray, material: Material, radius: float
) -> float | np.ndarray:
    """Solitary-wave speed from its peak force, Eq. 5 first form, m/s.

    v = (6 / (5 pi rho))^(1/2) (F_m / (theta^2 R^2))^(1/6).

    Parameters
    ----------
    peak_force : float or array
        Peak contact force F_m, N.
    material : Material
        Bead material (rho, theta).
    radius : float
        Bead radius R, m.
    """
    radius = require_positive("radius", radius)
    force = np.asarray(peak_force, dtype=float)
    speed = (6.0 / (5.0 * math.pi * material.density)) ** 0.5 * (
        force / (material.theta**2 * radius**2)
    ) ** (1.0 / 6.0)
    return float(speed) if np.ndim(speed) == 0 else speed


def nesterenko_speed_from_velocity(
    peak_bead_velocity: float | np.ndarray, material: Material
) -> float | np.ndarray:
    """Solitary-wave speed from the peak bead velocity, Eq. 5 second form, m/s.

    v = (6 / (5 pi rho))^(2/5) (V_m / theta^2)^(1/5).

    Parameters
    ----------
    peak_bead_velocity : float or array
        Peak bead velocity V_m, m/s.
    material : Material
        Bead material (rho, theta).
    """
    velocity = np.asarray(peak_bead_velocity, dtype=float)
    speed = (6.0 / (5.0 * math.pi * material.density)) ** 0.4 * (
        velocity / material.theta**2
    ) ** 0.2
    return float(speed) if np.ndim(speed) == 0 else speed


def bead_velocity_from_force(
    peak_force: float | np.ndarray, material: Material, radius: float
) -> float | np.ndarray:
    """Peak bead velocity V_m of a solitary wave of peak force F_m, m/s.

    Equating the two forms of Eq. 5:
    V_m = (6 / (5 pi rho))^(1/2) theta^(1/3) R^(-5/3) F_m^(5/6).

    Parameters
    ----------
    peak_force : float or array
        Peak force F_m, N.
    material : Material
        Bead material.
    radius : float
        Bead radius, m.
    """
    radius = require_positive("radius", radius)
    force = np.asarray(peak_force, dtype=float)
    velocity = _velocity_scale(material, radius) * force ** (5.0 / 6.0)
    return float(velocity) if np.ndim(velocity) == 0 else velocity


def _velocity_scale(material: Material, radius: float) -> float:
    # V_m = scale * F_m^(5/6): the prefactor of the V_m <-> F_m relation, one home.
    return (
        (6.0 / (5.0 * math.pi * material.density)) ** 0.5
        * material.theta ** (1.0 / 3.0)
        * radius ** (-5.0 / 3.0)
    )


def force_from_bead_velocity(
    peak_bead_velocity: float | np.ndarray, material: Material, radius: float
) -> float | np.ndarray:
    """Inverse of :func:`bead_velocity_from_force`: F_m (N) from the peak bead velocity
    V_m (m/s) of beads of ``material`` and ``radius`` (m)."""
    radius = require_positive("radius", radius)
    velocity = np.asarray(peak_bead_velocity, dtype=float)
    force = (velocity / _velocity_scale(material, radius)) ** 1.2
    return float(force) if np.ndim(force) == 0 else force


def pulse_half_width(peak_force: float | np.ndarray, material: Material, radius: float):
    """The time scale tau of the cos^6 pulse, tau = R sqrt(10) / v (Eq. 4), s.
    Parameters as in :func:`nesterenko_speed_from_force`."""
    return radius * math.sqrt(10.0) / nesterenko_speed_from_force(peak_force, material, radius)


def solitary_wave_length(radius: float) -> float:
    """Spatial extent of one hump of Eq. 4, pi R sqrt(10) (about five bead diameters), m,
    of beads of ``radius`` (m)."""
    return math.pi * math.sqrt(10.0) * require_positive("radius", radius)


def cos6_pulse(time, peak_force: float, arrival_time: float, tau: float) -> np.ndarray:
    """Nesterenko's pulse F_m cos^6((t - T)/tau) on one hump, zero outside, N.

    Parameters
    ----------
    time : array
        Times, s.
    peak_force : float
        F_m, N.
    arrival_time : float
        T, s (time of the peak).
    tau : float
        Time scale, s; the hump spans |t - T| < pi tau / 2.
    """
    phase = (np.asarray(time, dtype=float) - arrival_time) / tau
    return np.where(np.abs(phase) < math.pi / 2.0, peak_force * np.cos(phase) ** 6, 0.0)


def ballistic_delay_constant_paper(material: Material, radius: float) -> float:
    """C_bal exactly as printed in Eq. 6, in s N^(1/6).

    C_bal = 0.7612 (5 pi rho / 6)^(1/2) (theta R^4)^(1/3); 49.74 us N^(1/6) for the
    paper's 100C6 beads.

    Parameters
    ----------
    material : Material
        Bead material.
    radius : float
        Bead radius R, m.
    """
    radius = require_positive("radius", radius)
    return (
        PAPER_CBAL_PREFACTOR
        * (5.0 * math.pi * material.density / 6.0) ** 0.5
        * (material.theta * radius**4) ** (1.0 / 3.0)
    )


def ballistic_delay_constant_paper_first_line(material: Material, radius: float) -> float:
    """C_bal from the first line of Eq. 6 (2.94, mu = m) with V_m(F_m) from Eq. 5, s N^(1/6):
    equal to :func:`ballistic_delay_constant_paper` to the four digits printed (a check
    on the prefactor 0.7612). Parameters as there (material; bead radius R, m)."""
    mass, kappa, velocity_per_force = _ballistic_inputs(material, radius)
    time_scale = (5.0 * mass / (4.0 * kappa)) ** 0.4
    return PAPER_TIME_CONSTANT * time_scale * velocity_per_force ** (-0.2) * (1.0 - 2.0 ** (-0.2))


def ballistic_delay_constant_exact(material: Material, radius: float) -> float:
    """C_bal from the same ballistic argument with the exact Hertz contact time, s N^(1/6).

    Delta = t_c(V_m) - t_c(2 V_m) for two equal free beads (reduced mass m/2, exact
    constant 2.9432), with V_m(F_m) from Eq. 5 as in the paper:
    :data:`EXACT_OVER_PAPER_BALLISTIC` (0.759) times :func:`ballistic_delay_constant_paper`,
    whose parameters it takes (material; bead radius R, m).
    """
    mass, kappa, velocity = _ballistic_inputs(material, radius)
    return hertz_contact_time(mass, mass, kappa, velocity) - hertz_contact_time(
        mass, mass, kappa, 2.0 * velocity
    )


def _ballistic_inputs(material: Material, radius: float) -> tuple[float, float, float]:
    """What the ballistic argument of Eq. 6 starts from: the bead mass m (kg), the
    bead-bead contact stiffness kappa (N/m^(3/2)) and the peak bead velocity V_m of a
    solitary wave of F_m = 1 N (m/s, Eq. 5)."""
    return (
        sphere_mass(material, radius),
        contact_stiffness(material, radius, material, radius),
        bead_velocity_from_force(1.0, material, radius),
    )


def ballistic_delay(peak_force, delay_constant: float):
    """Delta = C F_m^(-1/6), in the units of ``delay_constant`` (s if C is in s N^(1/6)).

    Parameters
    ----------
    peak_force : float or array
        Incident peak force F_m, N.
    delay_constant : float
        C, s N^(1/6) (or us N^(1/6)).
    """
    return delay_constant * np.asarray(peak_force, dtype=float) ** (-1.0 / 6.0)


def _reduced_mass(mass_a: float, mass_b: float) -> float:
    # An infinite mass stands for a fixed wall.
    mass_a = mass_a if mass_a == math.inf else require_positive("mass_a", mass_a)
    mass_b = mass_b if mass_b == math.inf else require_positive("mass_b", mass_b)
    if math.isinf(mass_a) and math.isinf(mass_b):
        raise ValueError("mass_a and mass_b cannot both be infinite")
    if math.isinf(mass_a):
        return mass_b
    if math.isinf(mass_b):
        return mass_a
    return mass_a * mass_b / (mass_a + mass_b)


def ballistic_constants(material: str, radius_m: float) -> dict[str, float]:
    """Contact stiffness, bead mass and the two ballistic delay constants of a run:
    ``kappa_N_m1_5`` (N/m^1.5), ``bead_mass_kg``, ``C_bal_paper_us_N16`` (Eq. 6 as
    printed) and ``C_bal_exact_us_N16`` (the exact Hertz contact time), us N^(1/6).

    Parameters
    ----------
    material : str
        Bead material name (:data:`chain.physics.materials.MATERIALS`).
    radius_m : float
        Bead radius, m.
    """
    beads = get_material(material)
    return {
        "kappa_N_m1_5": contact_stiffness(beads, radius_m, beads, radius_m),
        "bead_mass_kg": sphere_mass(beads, radius_m),
        "C_bal_paper_us_N16": ballistic_delay_constant_paper(beads, radius_m) * 1e6,
        "C_bal_exact_us_N16": ballistic_delay_constant_exact(beads, radius_m) * 1e6,
    }


def pulse_passing_time(
    material: str,
    radius_m: float,
    n_beads: int,
    sensors: Sequence[int],
    v0_m_s: float,
    mass_ratio: float = 1.0,
) -> dict[str, float]:
    """When the slowest pulse has passed the far sensor (the duration check).

    Parameters
    ----------
    material : str
        Bead material name.
    radius_m : float
        Bead radius R, m.
    n_beads : int
        Number of beads N.
    sensors : sequence of int
        Sensor beads [S1, S2].
    v0_m_s : float
        Launch speed of the slowest wave, m/s (bead 1's, or the striker's).
    mass_ratio : float
        Launcher mass over bead mass (1 when bead 1 itself is launched).

    Returns
    -------
    dict
        ``force_N`` (estimated incident F_m), ``speed_m_s`` (Eq. 5), ``tau_s`` (Eq. 4),
        ``distance_m`` (launching end to the far sensor), ``bead`` (that sensor) and
        ``time_s`` = distance / speed + (pi/2) tau.
    """
    beads = get_material(material)
    s1, s2 = sensors[0], sensors[-1]
    bead, beads_away = (s2, s2 - 1) if s2 - 1 >= n_beads - s1 else (s1, n_beads - s1)
    distance = 2.0 * radius_m * beads_away
    force = force_from_bead_velocity(LAUNCH_VELOCITY_RATIO * mass_ratio * v0_m_s, beads, radius_m)
    speed = nesterenko_speed_from_force(force, beads, radius_m)
    tau = pulse_half_width(force, beads, radius_m)
    return {
        "force_N": force,
        "speed_m_s": speed,
        "tau_s": tau,
        "distance_m": distance,
        "bead": bead,
        "time_s": distance / speed + 0.5 * math.pi * tau,
    }
