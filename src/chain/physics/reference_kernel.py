"""The general RK4 kernel: the reference every fast path is tested against.

A second implementation: it handles every model by branching per link, copies the
state and looks for contact events with an extra pass over all links at every step,
and records every link and particle. :mod:`chain.physics.kernels` integrates the same
scheme with the same arithmetic, faster; ``tests/test_kernels.py`` checks that the two
agree bit for bit. Selected with ``integrate(..., kernel="reference")``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from chain.physics import compile_once, kernel_cache, safe_cache
from chain.physics.kernels import _NOT_FINITE, _OK, EVENT_AFTERMATH, EVENT_SUBSTEPS
from chain.physics.slopes import _hertz_force

#: numba's cache only in a folder no other account can write (chain.physics.safe_cache).
CACHE = safe_cache.allowed(__file__)


@numba.njit(cache=CACHE, inline="always")
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


@numba.njit(cache=CACHE)
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


@numba.njit(cache=CACHE)
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


@numba.njit(cache=CACHE, inline="always")
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


@numba.njit(cache=CACHE)
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


@numba.njit(cache=CACHE)
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


@compile_once.shared
@numba.njit(cache=CACHE, parallel=True)
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


# numba's cache does not see edits of kernels.py and slopes.py, whose constants and
# contact force these kernels use: checked here, before any of them runs
# (chain.physics.kernel_cache).
kernel_cache.forget_if_sources_changed(__name__, globals())
