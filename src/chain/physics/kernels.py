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
from numba import types
from numba.extending import overload

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
def _copy_into(target, source):
    # Element by element: numba compiles ``target[:] = source`` through its general
    # slice-assignment code, which made a cold compile several seconds longer.
    for p in range(source.shape[0]):
        target[p] = source[p]


@numba.njit(cache=True, inline="always")
def _all_finite(values):
    for p in range(values.shape[0]):
        if not math.isfinite(values[p]):
            return False
    return True


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


# The hot functions take the model's arrays one by one (taking them out of a tuple
# costs reference-count updates at every call), and the right-hand side is one flat
# loop over the links: a loop over runs of Hertz links between the sensor springs
# made it 2.5x slower than the bare loop. Their shared trailing arguments
# ``im, k, c, keys, springs, walls, drag`` are the model (see _integrate_one); ``c``,
# ``walls`` and ``drag`` are None when the model has no such term.


@numba.njit(cache=True)
def _walls(u, v, keys, walls):
    """(left force, right force, dissipated power, fingerprint) of the walls."""
    n = u.shape[0]
    power = 0.0
    left = 0.0
    right = 0.0
    mark = np.uint64(0)
    if walls[0, 0] > 0.0:
        elastic, left = _hertz_force(walls[0, 0], walls[0, 1], -u[0], -v[0])
        power -= (left - elastic) * v[0]
        if u[0] < 0.0:
            mark ^= keys[keys.shape[0] - 2]
    if walls[1, 0] > 0.0:
        elastic, right = _hertz_force(walls[1, 0], walls[1, 1], u[n - 1], v[n - 1])
        power += (right - elastic) * v[n - 1]
        if u[n - 1] > 0.0:
            mark ^= keys[keys.shape[0] - 1]
    return left, right, power, mark


# Dispatch on None at compile time. Not inline="always": with numba 0.68 an inlined
# overload made _record silently skip its energy writes; LLVM inlines these anyway
# (measured: same speed as the code written in place).
def _wall_terms(u, v, keys, walls):
    """_walls, or zeros when ``walls`` is None (decided when numba compiles)."""


@overload(_wall_terms)
def _wall_terms_overload(u, v, keys, walls):
    if walls is types.none:
        return lambda u, v, keys, walls: (0.0, 0.0, 0.0, np.uint64(0))
    return lambda u, v, keys, walls: _walls(u, v, keys, walls)


def _hertz_link(k, c, j, delta, v, power):
    """(force, power) of the closed Hertz link j: elastic when ``c`` is None, else with
    the Kuwabara-Kono term, its dissipated power added (decided when numba compiles)."""


@overload(_hertz_link)
def _hertz_link_overload(k, c, j, delta, v, power):
    if c is types.none:
        return lambda k, c, j, delta, v, power: (k[j] * delta * math.sqrt(delta), power)
    return lambda k, c, j, delta, v, power: _damped_link(k, c, j, delta, v, power)


@numba.njit(cache=True)
def _damped_link(k, c, j, delta, v, power):
    rate = v[j] - v[j + 1]
    elastic, total = _hertz_force(k[j], c[j], delta, rate)
    return total, power + (total - elastic) * rate


def _drag_terms(v, acc, drag, power):
    """Track friction into ``acc``; returns the power with its dissipation added."""


@overload(_drag_terms)
def _drag_terms_overload(v, acc, drag, power):
    if drag is types.none:
        return lambda v, acc, drag, power: power
    return lambda v, acc, drag, power: _drag(v, acc, drag, power)


def _wall_energy(u, walls, energy):
    """``energy`` plus the elastic energy of the wall contacts, J."""


@overload(_wall_energy)
def _wall_energy_overload(u, walls, energy):
    if walls is types.none:
        return lambda u, walls, energy: energy
    return lambda u, walls, energy: _walls_energy(u, walls, energy)


@numba.njit(cache=True)
def _drag(v, acc, drag, power):
    # drag[p] = (drag rate, mass x drag rate): the general kernel's m * g * v * v.
    for p in range(v.shape[0]):
        acc[p] -= drag[p, 0] * v[p]
        power += drag[p, 1] * v[p] * v[p]
    return power


@numba.njit(cache=True, inline="always")
def _slopes(u, v, acc, im, k, c, keys, springs, walls, drag):
    """Accelerations into ``acc``; returns (dissipated power, closed contacts, fingerprint).

    ``springs`` lists the bonded links in order and ends with n - 1 (no link);
    ``walls`` and ``drag`` are None when the model has none: numba then compiles a
    version without them (a branch on a flag made the loop 2x slower)."""
    n = u.shape[0]
    left = right = power = 0.0
    mark = np.uint64(0)
    left, right, power, mark = _wall_terms(u, v, keys, walls)
    # Wall ends counted for free ends too, as the general kernel does.
    closed = 0
    if u[0] < 0.0:
        closed += 1
    if u[n - 1] > 0.0:
        closed += 1
    previous = left
    spring = springs[0]
    s = 0
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        total = 0.0
        if j == spring:
            total = k[j] * delta
            s += 1
            spring = springs[s]
        elif delta > 0.0:
            closed += 1
            mark ^= keys[j]
            total, power = _hertz_link(k, c, j, delta, v, power)
        acc[j] = (previous - total) * im[j]
        previous = total
    acc[n - 1] = (previous - right) * im[n - 1]
    power = _drag_terms(v, acc, drag, power)
    return power, closed, mark


@numba.njit(cache=True, inline="always")
def _rk4(u, v, acc0, slope0, dt, buffers, im, k, c, keys, springs, walls, drag):
    """One RK4 step from (u, v), whose slopes ``acc0`` and ``slope0`` (power, closed,
    fingerprint) are known, into (u_out, v_out), the last two ``buffers``.

    Returns the dissipated energy of the step and whether the number of closed
    contacts varied between the stages. The weighted slopes are summed as they come,
    in the general kernel's order (0.0 + 1 k1 + 2 k2 + 2 k3 + 1 k4)."""
    acc, u_stage, v_stage, u_sum, v_sum, u_out, v_out = buffers
    n = u.shape[0]
    half = 0.5 * dt
    for p in range(n):
        u_sum[p] = 0.0 + v[p]
        v_sum[p] = 0.0 + acc0[p]
        u_stage[p] = u[p] + half * v[p]
        v_stage[p] = v[p] + half * acc0[p]
    power_sum = 0.0 + slope0[0]
    varied = False
    for stage in range(1, 4):
        power, closed, _ = _slopes(u_stage, v_stage, acc, im, k, c, keys, springs, walls, drag)
        varied = varied or closed != slope0[1]
        if stage == 3:
            break
        power_sum += 2.0 * power
        h = dt if stage == 2 else half
        for p in range(n):
            u_sum[p] += 2.0 * v_stage[p]
            v_sum[p] += 2.0 * acc[p]
            u_stage[p] = u[p] + h * v_stage[p]
            v_stage[p] = v[p] + h * acc[p]
    power_sum += power
    sixth = dt / 6.0
    for p in range(n):
        u_out[p] = u[p] + sixth * (u_sum[p] + v_stage[p])
        v_out[p] = v[p] + sixth * (v_sum[p] + acc[p])
    return sixth * power_sum, varied


@numba.njit(cache=True)
def _record(u, v, dissipated, model, links, particles, sample, outputs):
    """Writes sample ``sample``; returns False when the state is not finite.
    ``model`` = (masses, k, c, keys, walls, kind)."""
    out_link, out_wall, out_velocity, out_energy, out_momentum = outputs
    masses, k, c, keys, walls, kind = model
    left, right, _, _ = _wall_terms(u, v, keys, walls)
    for i in range(links.shape[0]):
        j = links[i]
        delta = u[j] - u[j + 1]
        if kind[j] == 1:
            out_link[sample, i] = k[j] * delta
        else:
            out_link[sample, i] = _hertz_force(k[j], c[j], delta, v[j] - v[j + 1])[1]
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
    out_energy[sample, 1] = _potential_energy(u, k, kind, walls)
    out_energy[sample, 2] = dissipated
    out_momentum[sample] = momentum
    return finite


@numba.njit(cache=True)
def _potential_energy(u, k, kind, walls):
    n = u.shape[0]
    energy = 0.0
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        if kind[j] == 1:
            energy += 0.5 * k[j] * delta * delta
        elif delta > 0.0:
            energy += 0.4 * k[j] * delta * delta * math.sqrt(delta)
    return _wall_energy(u, walls, energy)


@numba.njit(cache=True)
def _walls_energy(u, walls, energy):
    n = u.shape[0]
    if walls[0, 0] > 0.0 and u[0] < 0.0:
        delta = -u[0]
        energy += 0.4 * walls[0, 0] * delta * delta * math.sqrt(delta)
    if walls[1, 0] > 0.0 and u[n - 1] > 0.0:
        delta = u[n - 1]
        energy += 0.4 * walls[1, 0] * delta * delta * math.sqrt(delta)
    return energy


@numba.njit(cache=True)
def _substeps(x, acc, slope, dt, work, im, k, c, keys, springs, walls, drag):
    """EVENT_SUBSTEPS RK4 steps from the state x = (u, v, spare u, spare v) whose
    slopes are (``acc``, ``slope``); the end state is left in x[0], x[1] and ``acc``.
    Returns (dissipated energy, event seen, end slope)."""
    u, v, u_b, v_b = x
    acc_b = work[5]
    h = dt / EVENT_SUBSTEPS
    increment = 0.0
    event = False
    for _ in range(EVENT_SUBSTEPS):
        buffers = (work[0], work[1], work[2], work[3], work[4], u_b, v_b)
        part, varied = _rk4(u, v, acc, slope, h, buffers, im, k, c, keys, springs, walls, drag)
        slope = _slopes(u_b, v_b, acc_b, im, k, c, keys, springs, walls, drag)
        increment += part
        event = event or varied
        u, u_b = u_b, u
        v, v_b = v_b, v
        acc, acc_b = acc_b, acc
    if EVENT_SUBSTEPS % 2 == 1:  # the end state is in the spare buffers
        _copy_into(u_b, u)
        _copy_into(v_b, v)
        _copy_into(acc_b, acc)
    return increment, event, slope


@numba.njit(cache=True, inline="always")
def _step(
    x_u, x_v, x_acc, y_u, y_v, y_acc, work, slope, refine, dt, im, k, c, keys, springs, walls, drag
):
    """One step from the state in x (slopes ``x_acc``, ``slope``): the plain RK4 step
    into y, or, at a contact event and the EVENT_AFTERMATH steps after it (``refine``
    > 0), EVENT_SUBSTEPS substeps whose end state is left in x. Returns (dissipated
    energy, end slope, refine, whether the step was refined, whether the state moved
    to y).

    Inlined at two call sites, one per order of the arrays, so that the loop never
    swaps array variables: a swap costs reference-count updates (measured: the paper's
    collision ran 9-12 % faster without them, same bits; the price is a longer cold
    compilation)."""
    if refine == 0:
        buffers = (work[0], work[1], work[2], work[3], work[4], y_u, y_v)
        increment, varied = _rk4(
            x_u, x_v, x_acc, slope, dt, buffers, im, k, c, keys, springs, walls, drag
        )
        end = _slopes(y_u, y_v, y_acc, im, k, c, keys, springs, walls, drag)
        if not (varied or end[2] != slope[2]):
            return increment, end, refine, False, True
        refine = EVENT_AFTERMATH + 1
    increment, varied, end = _substeps(
        (x_u, x_v, y_u, y_v), x_acc, slope, dt, work, im, k, c, keys, springs, walls, drag
    )
    refine -= 1
    if varied or end[2] != slope[2]:
        refine = EVENT_AFTERMATH
    return increment, end, refine, True, False


@numba.njit(cache=True, nogil=True)
def _integrate_one(u, v, params, dt, n_steps, record_every, links, particles, outputs):
    """RK4 for one launch; ``u`` and ``v`` end as the final state. Returns the status,
    the step at which it was set, and the number of steps refined at contact events."""
    im, masses, k, damping, keys, springs, walls, drag, kind, c = params
    # Unpacked once: a tuple holding None gives wrong elements inside some callees.
    recorded = (masses, k, damping, keys, walls, kind)
    n = u.shape[0]
    work = (np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n))
    x_u, x_v, x_acc = np.empty(n), np.empty(n), np.empty(n)
    _copy_into(x_u, u)
    _copy_into(x_v, v)
    y_u, y_v, y_acc = np.empty(n), np.empty(n), np.empty(n)
    slope = _slopes(x_u, x_v, x_acc, im, k, c, keys, springs, walls, drag)
    dissipated = 0.0
    _record(x_u, x_v, dissipated, recorded, links, particles, 0, outputs)
    refine = refined = step = 0
    in_y = False  # the state is in (y_u, y_v, y_acc), else in (x_u, x_v, x_acc)
    status = _OK
    while step < n_steps and status == _OK:
        step += 1
        if in_y:
            increment, slope, refine, substeps, moved = _step(
                y_u,
                y_v,
                y_acc,
                x_u,
                x_v,
                x_acc,
                work,
                slope,
                refine,
                dt,
                im,
                k,
                c,
                keys,
                springs,
                walls,
                drag,
            )
        else:
            increment, slope, refine, substeps, moved = _step(
                x_u,
                x_v,
                x_acc,
                y_u,
                y_v,
                y_acc,
                work,
                slope,
                refine,
                dt,
                im,
                k,
                c,
                keys,
                springs,
                walls,
                drag,
            )
        refined += substeps
        in_y = in_y != moved
        dissipated += increment
        if step % record_every == 0:
            sample = step // record_every
            if in_y:
                finite = _record(y_u, y_v, dissipated, recorded, links, particles, sample, outputs)
            else:
                finite = _record(x_u, x_v, dissipated, recorded, links, particles, sample, outputs)
            if not finite:
                status = _NOT_FINITE
    if in_y:
        _copy_into(x_u, y_u)
        _copy_into(x_v, y_v)
    if status == _OK and not (_all_finite(x_u) and _all_finite(x_v)):
        status = _NOT_FINITE
    _copy_into(u, x_u)
    _copy_into(v, x_v)
    return status, step, refined
