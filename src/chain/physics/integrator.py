"""Fixed-step classical RK4 for a :class:`~chain.physics.model.ChainModel` (the paper's method).

The private numba kernels take flat arrays and write into preallocated outputs;
:func:`integrate` checks its inputs, allocates, and turns a failed run into an
:class:`IntegrationError`. The state integrated per launch is (u, v, E_diss): the
dissipated energy is integrated with the same RK4 so that
E_kin + E_pot + E_diss is conserved to the scheme's accuracy with or without
dissipation, which makes the energy drift a check on the step in every run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from chain.errors import ParameterError, require_positive
from chain.physics.model import HERTZ, SPRING, ChainModel

#: Status codes written by the kernel.
_OK = 0
_NOT_FINITE = 1

#: Default bound on the relative energy drift before a run is declared broken.
DEFAULT_MAX_ENERGY_DRIFT = 1e-6


class IntegrationError(RuntimeError):
    """The integration failed (blow-up or energy drift above threshold)."""


#: Contact events (a Hertz contact opening or closing) are integrated in
#: EVENT_SUBSTEPS substeps, for the step where they happen and the EVENT_AFTERMATH
#: steps after it: the force kappa delta^(3/2) has an unbounded second derivative at
#: delta = 0, which costs RK4 its order on exactly those steps.
EVENT_SUBSTEPS = 16
EVENT_AFTERMATH = 3


@numba.njit(cache=True, inline="always")
def _hertz_force(stiffness, damping, delta, delta_rate):
    # Returns (elastic, total); total is clipped at zero because a contact never pulls.
    if delta <= 0.0:
        return 0.0, 0.0
    root = math.sqrt(delta)
    elastic = stiffness * delta * root
    if damping == 0.0:
        return elastic, elastic
    total = elastic + damping * root * delta_rate
    if total < 0.0:
        total = 0.0
    return elastic, total


@numba.njit(cache=True, inline="always")
def _derivatives(u, v, params, acc, link_force):
    """Accelerations into ``acc``, link forces into ``link_force``; returns
    (left wall force, right wall force, dissipated power, closed Hertz contacts)."""
    (
        masses,
        inverse_mass,
        link_kind,
        link_stiffness,
        link_damping,
        wall_stiffness,
        wall_damping,
        drag_rate,
        has_drag,
    ) = params
    n = u.shape[0]
    power = 0.0
    left = 0.0
    right = 0.0
    if wall_stiffness[0] > 0.0:
        elastic, left = _hertz_force(wall_stiffness[0], wall_damping[0], -u[0], -v[0])
        power -= (left - elastic) * v[0]
    if wall_stiffness[1] > 0.0:
        elastic, right = _hertz_force(wall_stiffness[1], wall_damping[1], u[n - 1], v[n - 1])
        power += (right - elastic) * v[n - 1]
    # One pass: particle j feels the force of the link on its left (previous) and right.
    closed = (u[0] < 0.0) + (u[n - 1] > 0.0)
    previous = left
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        if link_kind[j] == 1:
            total = link_stiffness[j] * delta
        elif delta > 0.0:
            closed += 1
            rate = v[j] - v[j + 1]
            elastic, total = _hertz_force(link_stiffness[j], link_damping[j], delta, rate)
            power += (total - elastic) * rate
        else:
            total = 0.0
        link_force[j] = total
        acc[j] = (previous - total) * inverse_mass[j]
        previous = total
    acc[n - 1] = (previous - right) * inverse_mass[n - 1]
    if has_drag:
        for p in range(n):
            acc[p] -= drag_rate[p] * v[p]
            power += masses[p] * drag_rate[p] * v[p] * v[p]
    return left, right, power, closed


@numba.njit(cache=True)
def _potential_energy(u, params):
    link_kind, link_stiffness, wall_stiffness = params[2], params[3], params[5]
    n = u.shape[0]
    energy = 0.0
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        if link_kind[j] == 1:
            energy += 0.5 * link_stiffness[j] * delta * delta
        elif delta > 0.0:
            energy += 0.4 * link_stiffness[j] * delta * delta * math.sqrt(delta)
    if wall_stiffness[0] > 0.0 and u[0] < 0.0:
        delta = -u[0]
        energy += 0.4 * wall_stiffness[0] * delta * delta * math.sqrt(delta)
    if wall_stiffness[1] > 0.0 and u[n - 1] > 0.0:
        delta = u[n - 1]
        energy += 0.4 * wall_stiffness[1] * delta * delta * math.sqrt(delta)
    return energy


@numba.njit(cache=True)
def _record(u, v, dissipated, params, acc, link_force, sample, outputs):
    out_link_force, out_wall_force, out_velocity, out_energy, out_momentum = outputs
    masses = params[0]
    left, right, _, _ = _derivatives(u, v, params, acc, link_force)
    kinetic = 0.0
    momentum = 0.0
    for p in range(u.shape[0]):
        kinetic += 0.5 * masses[p] * v[p] * v[p]
        momentum += masses[p] * v[p]
        out_velocity[sample, p] = v[p]
    for j in range(out_link_force.shape[1]):
        out_link_force[sample, j] = link_force[j]
    out_wall_force[sample, 0] = left
    out_wall_force[sample, 1] = right
    out_energy[sample, 0] = kinetic
    out_energy[sample, 1] = _potential_energy(u, params)
    out_energy[sample, 2] = dissipated
    out_momentum[sample] = momentum


@numba.njit(cache=True, inline="always")
def _rk4_step(u, v, dt, params, work):
    """One classical RK4 step of (u, v) in place; returns the dissipated energy and
    whether the number of closed contacts varied between the stages (a contact event
    inside the step, even one that closes and reopens within it)."""
    acc, link_force, u_stage, v_stage, u_sum, v_sum = work
    n = u.shape[0]
    for p in range(n):
        u_stage[p] = u[p]
        v_stage[p] = v[p]
        u_sum[p] = 0.0
        v_sum[p] = 0.0
    power_sum = 0.0
    half = 0.5 * dt
    first_closed = -1
    varied = False
    # The weighted slopes are summed as they come, so no stage is stored.
    for stage in range(4):
        _, _, power, closed = _derivatives(u_stage, v_stage, params, acc, link_force)
        if stage == 0:
            first_closed = closed
        elif closed != first_closed:
            varied = True
        weight = 1.0 if stage == 0 or stage == 3 else 2.0
        h = dt if stage == 2 else half
        power_sum += weight * power
        for p in range(n):
            u_sum[p] += weight * v_stage[p]
            v_sum[p] += weight * acc[p]
            if stage < 3:
                u_stage[p] = u[p] + h * v_stage[p]
                v_stage[p] = v[p] + h * acc[p]
    sixth = dt / 6.0
    for p in range(n):
        u[p] += sixth * u_sum[p]
        v[p] += sixth * v_sum[p]
    return sixth * power_sum, varied


@numba.njit(cache=True)
def _contact_changed(u_before, u_after, params):
    """True when a Hertz contact (or wall) opened or closed between two states."""
    link_kind, wall_stiffness = params[2], params[5]
    n = u_before.shape[0]
    for j in range(n - 1):
        if link_kind[j] != 1:
            if (u_before[j] - u_before[j + 1] > 0.0) != (u_after[j] - u_after[j + 1] > 0.0):
                return True
    if wall_stiffness[0] > 0.0 and (u_before[0] < 0.0) != (u_after[0] < 0.0):
        return True
    if wall_stiffness[1] > 0.0 and (u_before[n - 1] > 0.0) != (u_after[n - 1] > 0.0):
        return True
    return False


@numba.njit(cache=True)
def _integrate_one(u, v, params, dt, n_steps, record_every, outputs):
    """RK4 for one launch; ``u`` and ``v`` are updated in place. Returns the status,
    the step at which it was set, and the number of steps refined at contact events."""
    n = u.shape[0]
    work = (
        np.empty(n),
        np.empty(max(n - 1, 1)),
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(n),
    )
    u_start = np.empty(n)
    v_start = np.empty(n)
    dissipated = 0.0
    _record(u, v, dissipated, params, work[0], work[1], 0, outputs)
    substep = dt / EVENT_SUBSTEPS
    refine = 0
    refined = 0
    for step in range(1, n_steps + 1):
        for p in range(n):
            u_start[p] = u[p]
            v_start[p] = v[p]
        coarse = refine == 0
        if coarse:
            increment, varied = _rk4_step(u, v, dt, params, work)
            if varied or _contact_changed(u_start, u, params):
                for p in range(n):
                    u[p] = u_start[p]
                    v[p] = v_start[p]
                coarse = False
                refine = EVENT_AFTERMATH + 1
        if not coarse:
            increment = 0.0
            event = False
            for _ in range(EVENT_SUBSTEPS):
                part, varied = _rk4_step(u, v, substep, params, work)
                increment += part
                event = event or varied
            refine -= 1
            refined += 1
            if event or _contact_changed(u_start, u, params):
                refine = EVENT_AFTERMATH
        dissipated += increment
        for p in range(n):
            if not (math.isfinite(u[p]) and math.isfinite(v[p])):
                return _NOT_FINITE, step, refined
        if step % record_every == 0:
            _record(u, v, dissipated, params, work[0], work[1], step // record_every, outputs)
    return _OK, n_steps, refined


@numba.njit(cache=True, parallel=True)
def _integrate_batch(
    u,
    v,
    params,
    dt,
    n_steps,
    record_every,
    out_link_force,
    out_wall_force,
    out_velocity,
    out_energy,
    out_momentum,
    out_status,
    out_fail_step,
    out_refined,
):
    # Launches are independent: one thread each, so results do not depend on the
    # number of threads.
    for b in numba.prange(u.shape[0]):
        outputs = (
            out_link_force[b],
            out_wall_force[b],
            out_velocity[b],
            out_energy[b],
            out_momentum[b],
        )
        status, step, refined = _integrate_one(
            u[b], v[b], params, dt, n_steps, record_every, outputs
        )
        out_status[b] = status
        out_fail_step[b] = step
        out_refined[b] = refined


@dataclass(frozen=True)
class RawTrajectory:
    """Particle-level output of :func:`integrate`; :mod:`chain.physics.simulation` maps it to beads.

    Attributes
    ----------
    time : (S,) s
    link_force : (B, S, P-1) N, compression positive
    wall_force : (B, S, 2) N, left and right wall contact forces
    velocity : (B, S, P) m/s
    energy : (B, S, 3) J: kinetic, potential (Hertz + springs), dissipated so far
    momentum : (B, S) kg m/s
    final_displacement, final_velocity : (B, P) m, m/s
    dt : s, the step used
    refined_steps : (B,) steps integrated in EVENT_SUBSTEPS substeps (contact events)
    """

    time: np.ndarray
    link_force: np.ndarray
    wall_force: np.ndarray
    velocity: np.ndarray
    energy: np.ndarray
    momentum: np.ndarray
    final_displacement: np.ndarray
    final_velocity: np.ndarray
    dt: float
    refined_steps: np.ndarray

    @property
    def total_energy(self) -> np.ndarray:
        """E_kin + E_pot + E_diss, (B, S) J: constant up to integration error."""
        return self.energy.sum(axis=2)

    @property
    def energy_drift(self) -> np.ndarray:
        """Largest |E(t) - E(0)| / E(0) over the recorded samples, per launch, (B,)."""
        total = self.total_energy
        reference = np.abs(total[:, :1])
        reference = np.where(reference > 0, reference, 1.0)
        return np.max(np.abs(total - total[:, :1]) / reference, axis=1)


def integrate(
    model: ChainModel,
    initial_velocity: np.ndarray,
    duration: float,
    dt: float,
    record_every: int = 1,
    initial_displacement: np.ndarray | None = None,
    max_energy_drift: float = DEFAULT_MAX_ENERGY_DRIFT,
) -> RawTrajectory:
    """Integrate a batch of launches of ``model`` with fixed-step RK4.

    Parameters
    ----------
    model : ChainModel
        The chain.
    initial_velocity : array (B, P) or (P,)
        Particle velocities at t = 0, m/s.
    duration : float
        Simulated time, s; the run takes ceil(duration / dt) steps.
    dt : float
        Time step, s.
    record_every : int
        Record every this many steps (decimation), >= 1.
    initial_displacement : array (B, P) or (P,), optional
        Particle displacements at t = 0, m (default 0: beads barely touching).
    max_energy_drift : float
        Raise :class:`IntegrationError` when the relative drift of
        E_kin + E_pot + E_diss exceeds this; ``math.inf`` disables the check.

    Returns
    -------
    RawTrajectory
    """
    duration = require_positive("duration", duration)
    dt = require_positive("dt", dt)
    if not isinstance(record_every, int | np.integer) or record_every < 1:
        raise ParameterError(f"record_every must be an integer >= 1, got {record_every!r}")
    if not (max_energy_drift > 0):
        raise ParameterError(f"max_energy_drift must be > 0, got {max_energy_drift!r}")
    n_particles = model.n_particles
    velocity = _batch_array("initial_velocity", initial_velocity, n_particles)
    if initial_displacement is None:
        displacement = np.zeros_like(velocity)
    else:
        displacement = _batch_array("initial_displacement", initial_displacement, n_particles)
        if displacement.shape != velocity.shape:
            raise ParameterError(
                "initial_displacement and initial_velocity must have the same shape, got "
                f"{displacement.shape} and {velocity.shape}"
            )
    n_steps = math.ceil(duration / dt - 1e-9)
    record_every = int(record_every)
    n_samples = n_steps // record_every + 1
    batch = velocity.shape[0]
    n_links = max(n_particles - 1, 1)
    link_force = np.zeros((batch, n_samples, n_links))
    wall_force = np.zeros((batch, n_samples, 2))
    recorded_velocity = np.zeros((batch, n_samples, n_particles))
    energy = np.zeros((batch, n_samples, 3))
    momentum = np.zeros((batch, n_samples))
    status = np.zeros(batch, dtype=np.int64)
    fail_step = np.zeros(batch, dtype=np.int64)
    refined = np.zeros(batch, dtype=np.int64)
    link_damping = 1.5 * model.link_eta * model.link_stiffness
    link_damping[model.link_kind == SPRING] = 0.0
    params = (
        np.ascontiguousarray(model.masses, dtype=float),
        1.0 / model.masses,
        np.ascontiguousarray(model.link_kind, dtype=np.int64),
        np.ascontiguousarray(model.link_stiffness, dtype=float),
        link_damping,
        np.ascontiguousarray(model.wall_stiffness, dtype=float),
        1.5 * model.wall_eta * model.wall_stiffness,
        np.ascontiguousarray(model.drag_rate, dtype=float),
        bool(np.any(model.drag_rate > 0)),
    )
    _integrate_batch(
        displacement,
        velocity,
        params,
        dt,
        n_steps,
        record_every,
        link_force,
        wall_force,
        recorded_velocity,
        energy,
        momentum,
        status,
        fail_step,
        refined,
    )
    if np.any(status != _OK):
        b = int(np.flatnonzero(status != _OK)[0])
        raise IntegrationError(
            f"integration blew up (non-finite state) in launch {b} at step {fail_step[b]} "
            f"(t = {fail_step[b] * dt:.3e} s) with dt = {dt:.3e} s: the time step is too "
            "large for this run; reduce dt"
        )
    trajectory = RawTrajectory(
        time=np.arange(n_samples) * (record_every * dt),
        link_force=link_force[:, :, : n_particles - 1],
        wall_force=wall_force,
        velocity=recorded_velocity,
        energy=energy,
        momentum=momentum,
        final_displacement=displacement,
        final_velocity=velocity,
        dt=dt,
        refined_steps=refined,
    )
    drift = trajectory.energy_drift
    if np.any(drift > max_energy_drift):
        b = int(np.argmax(drift))
        raise IntegrationError(
            f"relative energy drift {drift[b]:.2e} in launch {b} exceeds max_energy_drift = "
            f"{max_energy_drift:.1e} with dt = {dt:.3e} s: the time step is too large for "
            "this run; reduce dt"
        )
    return trajectory


def _batch_array(name: str, values, n_particles: int) -> np.ndarray:
    array = np.array(values, dtype=float, ndmin=1)
    if array.ndim == 1:
        array = array[None, :]
    if array.ndim != 2 or array.shape[1] != n_particles:
        raise ParameterError(
            f"{name} must have shape (B, {n_particles}) or ({n_particles},), got {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"{name} contains non-finite values")
    return np.ascontiguousarray(array)


__all__ = ["HERTZ", "SPRING", "IntegrationError", "RawTrajectory", "integrate"]
