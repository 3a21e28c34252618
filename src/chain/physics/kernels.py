"""The lean RK4 kernel behind :func:`chain.physics.integrator.integrate`.

Same scheme and the same floating-point operations, in the same order, as the general
kernel (:mod:`chain.physics.reference_kernel`), so the two give bit-identical results;
what changed is the bookkeeping around the arithmetic:

* **First same as last.** The slopes at the end of a step are the first stage of the
  next one, so every step evaluates the right-hand side exactly four times, and the
  new state goes to a second buffer instead of over a saved copy.
* **Contact events for free.** RK4 loses its order on a step where a Hertz contact
  opens or closes (the force kappa delta^(3/2) has an unbounded second derivative at
  delta = 0), so such a step, and the EVENT_AFTERMATH steps after it, are redone in
  EVENT_SUBSTEPS substeps. The right-hand side counts the closed contacts and XORs a
  random 64-bit key of each into a fingerprint of the set of closed contacts; a step
  has an event when the count differs between its stages or the fingerprint differs
  between its two ends (two different sets share a fingerprint with probability
  2^-64). No pass over the links and no array is spent on it.
* **Links in runs.** Bonded sensor springs split the Hertz links into runs, so the
  inner loop has no per-link kind test; the Kuwabara-Kono term is one flag per model.
* **Only what is asked is recorded**: chosen links and particles, the two wall
  forces, the energies and the momentum. The state is checked for non-finite values
  at recorded samples only (a non-finite value never becomes finite again).
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: Status codes written by the kernels.
_OK = 0
_NOT_FINITE = 1

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
def _walls(u, v, params):
    """(left force, right force, dissipated power, closed walls, fingerprint) of the walls."""
    wall_k, wall_c, keys = params[6], params[7], params[4]
    n = u.shape[0]
    power = 0.0
    left = 0.0
    right = 0.0
    mark = np.uint64(0)
    if wall_k[0] > 0.0:
        elastic, left = _hertz_force(wall_k[0], wall_c[0], -u[0], -v[0])
        power -= (left - elastic) * v[0]
        if u[0] < 0.0:
            mark ^= keys[keys.shape[0] - 2]
    if wall_k[1] > 0.0:
        elastic, right = _hertz_force(wall_k[1], wall_c[1], u[n - 1], v[n - 1])
        power += (right - elastic) * v[n - 1]
        if u[n - 1] > 0.0:
            mark ^= keys[keys.shape[0] - 1]
    # Counted for free ends too, as the general kernel does.
    closed = (u[0] < 0.0) + (u[n - 1] > 0.0)
    return left, right, power, closed, mark


@numba.njit(cache=True, inline="always")
def _hertz_run(u, v, params, acc, start, stop, previous, power, closed, mark):
    """Hertz links start..stop-1 (no spring among them); returns the running sums."""
    inverse_mass, stiffness, damping, keys, damped = (
        params[0],
        params[2],
        params[3],
        params[4],
        params[10],
    )
    for j in range(start, stop):
        delta = u[j] - u[j + 1]
        total = 0.0
        if delta > 0.0:
            closed += 1
            mark ^= keys[j]
            if damped:
                rate = v[j] - v[j + 1]
                elastic, total = _hertz_force(stiffness[j], damping[j], delta, rate)
                power += (total - elastic) * rate
            else:
                total = stiffness[j] * delta * math.sqrt(delta)
        acc[j] = (previous - total) * inverse_mass[j]
        previous = total
    return previous, power, closed, mark


@numba.njit(cache=True, inline="always")
def _slopes(u, v, params, acc):
    """Accelerations into ``acc``; returns (dissipated power, closed contacts, fingerprint)."""
    inverse_mass, masses, stiffness, springs, drag_rate, has_drag = (
        params[0],
        params[1],
        params[2],
        params[5],
        params[8],
        params[11],
    )
    n = u.shape[0]
    left, right, power, closed, mark = _walls(u, v, params)
    previous = left
    start = 0
    # springs lists the bonded links in order and ends with n - 1 (no link).
    for s in range(springs.shape[0]):
        stop = springs[s]
        previous, power, closed, mark = _hertz_run(
            u, v, params, acc, start, stop, previous, power, closed, mark
        )
        if stop < n - 1:
            total = stiffness[stop] * (u[stop] - u[stop + 1])
            acc[stop] = (previous - total) * inverse_mass[stop]
            previous = total
        start = stop + 1
    acc[n - 1] = (previous - right) * inverse_mass[n - 1]
    if has_drag:
        for p in range(n):
            acc[p] -= drag_rate[p] * v[p]
            power += masses[p] * drag_rate[p] * v[p] * v[p]
    return power, closed, mark


@numba.njit(cache=True, inline="always")
def _rk4(u, v, acc0, power0, closed0, dt, params, work, u_out, v_out):
    """One RK4 step from (u, v), whose slopes ``acc0`` are known, into (u_out, v_out).

    Returns the dissipated energy of the step and whether the number of closed
    contacts varied between the stages. The weighted slopes are summed as they come,
    in the general kernel's order (0.0 + 1 k1 + 2 k2 + 2 k3 + 1 k4)."""
    acc, u_stage, v_stage, u_sum, v_sum = work
    n = u.shape[0]
    half = 0.5 * dt
    for p in range(n):
        u_sum[p] = 0.0 + v[p]
        v_sum[p] = 0.0 + acc0[p]
        u_stage[p] = u[p] + half * v[p]
        v_stage[p] = v[p] + half * acc0[p]
    power_sum = 0.0 + power0
    varied = False
    for stage in range(1, 3):
        power, closed, _ = _slopes(u_stage, v_stage, params, acc)
        varied = varied or closed != closed0
        power_sum += 2.0 * power
        h = dt if stage == 2 else half
        for p in range(n):
            u_sum[p] += 2.0 * v_stage[p]
            v_sum[p] += 2.0 * acc[p]
            u_stage[p] = u[p] + h * v_stage[p]
            v_stage[p] = v[p] + h * acc[p]
    power, closed, _ = _slopes(u_stage, v_stage, params, acc)
    varied = varied or closed != closed0
    power_sum += power
    sixth = dt / 6.0
    for p in range(n):
        u_out[p] = u[p] + sixth * (u_sum[p] + v_stage[p])
        v_out[p] = v[p] + sixth * (v_sum[p] + acc[p])
    return sixth * power_sum, varied


@numba.njit(cache=True)
def _substeps(u, v, acc, slope, params, dt, work, spare):
    """EVENT_SUBSTEPS RK4 steps from (u, v, acc) whose first-stage results are
    ``slope`` = (power, closed, fingerprint); the end state is written back into
    (u, v, acc). Returns (dissipated energy, event seen, end slope)."""
    u_b, v_b, acc_b = spare
    h = dt / EVENT_SUBSTEPS
    increment = 0.0
    event = False
    for _ in range(EVENT_SUBSTEPS):
        part, varied = _rk4(u, v, acc, slope[0], slope[1], h, params, work, u_b, v_b)
        slope = _slopes(u_b, v_b, params, acc_b)
        increment += part
        event = event or varied
        u, u_b = u_b, u
        v, v_b = v_b, v
        acc, acc_b = acc_b, acc
    if EVENT_SUBSTEPS % 2 == 1:  # the end state is in the spare buffers
        u_b[:] = u
        v_b[:] = v
        acc_b[:] = acc
    return increment, event, slope


@numba.njit(cache=True)
def _record(u, v, dissipated, params, links, particles, sample, outputs):
    """Writes sample ``sample``; returns False when the state is not finite."""
    out_link, out_wall, out_velocity, out_energy, out_momentum = outputs
    masses, stiffness, damping, link_kind = params[1], params[2], params[3], params[9]
    left, right, _, _, _ = _walls(u, v, params)
    for i in range(links.shape[0]):
        j = links[i]
        delta = u[j] - u[j + 1]
        if link_kind[j] == 1:
            out_link[sample, i] = stiffness[j] * delta
        else:
            out_link[sample, i] = _hertz_force(stiffness[j], damping[j], delta, v[j] - v[j + 1])[1]
    for i in range(particles.shape[0]):
        out_velocity[sample, i] = v[particles[i]]
    kinetic = 0.0
    momentum = 0.0
    finite = True
    for p in range(u.shape[0]):
        kinetic += 0.5 * masses[p] * v[p] * v[p]
        momentum += masses[p] * v[p]
        finite = finite and math.isfinite(u[p]) and math.isfinite(v[p])
    out_wall[sample, 0] = left
    out_wall[sample, 1] = right
    out_energy[sample, 0] = kinetic
    out_energy[sample, 1] = _potential_energy(u, params)
    out_energy[sample, 2] = dissipated
    out_momentum[sample] = momentum
    return finite


@numba.njit(cache=True)
def _potential_energy(u, params):
    stiffness, wall_k, link_kind = params[2], params[6], params[9]
    n = u.shape[0]
    energy = 0.0
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        if link_kind[j] == 1:
            energy += 0.5 * stiffness[j] * delta * delta
        elif delta > 0.0:
            energy += 0.4 * stiffness[j] * delta * delta * math.sqrt(delta)
    if wall_k[0] > 0.0 and u[0] < 0.0:
        delta = -u[0]
        energy += 0.4 * wall_k[0] * delta * delta * math.sqrt(delta)
    if wall_k[1] > 0.0 and u[n - 1] > 0.0:
        delta = u[n - 1]
        energy += 0.4 * wall_k[1] * delta * delta * math.sqrt(delta)
    return energy


@numba.njit(cache=True)
def _integrate_one(u, v, params, dt, n_steps, record_every, links, particles, outputs):
    """RK4 for one launch; ``u`` and ``v`` end as the final state. Returns the status,
    the step at which it was set, and the number of steps refined at contact events."""
    n = u.shape[0]
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    spare = (np.empty(n), np.empty(n), np.empty(n))
    x_u, x_v, x_acc = u.copy(), v.copy(), np.empty(n)
    slope = _slopes(x_u, x_v, params, x_acc)
    dissipated = 0.0
    _record(x_u, x_v, dissipated, params, links, particles, 0, outputs)
    refine = 0
    refined = 0
    status = _OK
    step = 0
    while step < n_steps and status == _OK:
        step += 1
        event = refine > 0
        if not event:
            u_b, v_b, acc_b = spare
            increment, varied = _rk4(
                x_u, x_v, x_acc, slope[0], slope[1], dt, params, work, u_b, v_b
            )
            end = _slopes(u_b, v_b, params, acc_b)
            event = varied or end[2] != slope[2]
            if event:
                refine = EVENT_AFTERMATH + 1
            else:
                spare = (x_u, x_v, x_acc)
                x_u, x_v, x_acc = u_b, v_b, acc_b
        if event:
            increment, varied, end = _substeps(x_u, x_v, x_acc, slope, params, dt, work, spare)
            refine -= 1
            refined += 1
            if varied or end[2] != slope[2]:
                refine = EVENT_AFTERMATH
        slope = end
        dissipated += increment
        if step % record_every == 0:
            sample = step // record_every
            if not _record(x_u, x_v, dissipated, params, links, particles, sample, outputs):
                status = _NOT_FINITE
    if status == _OK and not (np.all(np.isfinite(x_u)) and np.all(np.isfinite(x_v))):
        status = _NOT_FINITE
    u[:] = x_u
    v[:] = x_v
    return status, step, refined


@numba.njit(cache=True, parallel=True)
def _integrate_batch(
    u, v, params, dt, n_steps, record_every, links, particles, outputs, status, fail_step, refined
):
    # Launches are independent: one thread each, so results do not depend on the
    # number of threads.
    out_link, out_wall, out_velocity, out_energy, out_momentum = outputs
    for b in numba.prange(u.shape[0]):
        one = (out_link[b], out_wall[b], out_velocity[b], out_energy[b], out_momentum[b])
        result = _integrate_one(
            u[b], v[b], params, dt, n_steps, record_every, links, particles, one
        )
        status[b] = result[0]
        fail_step[b] = result[1]
        refined[b] = result[2]
