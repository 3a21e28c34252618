"""The lean RK4 kernel behind :func:`chain.physics.integrator.integrate`; its right-hand
side is :mod:`chain.physics.slopes`.

Same scheme and the same floating-point operations, in the same order, as the general
kernel (:mod:`chain.physics.reference_kernel`), so the two give bit-identical results;
only the bookkeeping around the arithmetic differs:

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
* **Elastic links vectorised.** The elastic right-hand side runs in passes with no
  branch on the link kind (every link as a Hertz contact, the bonded sensor springs
  over them, then the accelerations), so that numba's LLVM computes several links per
  SIMD instruction; the Kuwabara-Kono term is one flag per model.
* **One RK4 step for plain steps and substeps**, compiled once by numba and inlined
  by LLVM where it is called.
* **Only what is asked is recorded**: chosen links and particles, the two wall
  forces, the energies and the momentum. The state is checked for non-finite values
  at recorded samples only (a non-finite value never becomes finite again).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from chain.physics import compile_once, kernel_cache, safe_cache
from chain.physics.slopes import _hertz_force, _slopes, _wall_energy, _wall_terms

#: numba's cache only in a folder no other account can write (chain.physics.safe_cache).
CACHE = safe_cache.allowed(__file__)

#: Status codes written by the kernels.
_OK = 0
_NOT_FINITE = 1

#: Contact events (a Hertz contact opening or closing) are integrated in
#: EVENT_SUBSTEPS substeps, for the step where they happen and the EVENT_AFTERMATH
#: steps after it (see above).
EVENT_SUBSTEPS = 16
EVENT_AFTERMATH = 3

#: Beads at rest kept between the beads that move and the beads a run skips
#: (:mod:`chain.physics.at_rest`): a refined step spreads a disturbance by at most
#: 4 EVENT_SUBSTEPS beads (one per right-hand side), so the skipped beads never move
#: within a step.
QUIET_MARGIN = 4 * EVENT_SUBSTEPS + 4


@numba.njit(cache=CACHE, inline="always")
def _copy_into(target, source):
    # Element by element: numba compiles ``target[:] = source`` through its general
    # slice-assignment code, which made a cold compile several seconds longer.
    for p in range(source.shape[0]):
        target[p] = source[p]


@numba.njit(cache=CACHE, inline="always")
def _all_finite(values):
    for p in range(values.shape[0]):
        if not math.isfinite(values[p]):
            return False
    return True


@numba.njit(cache=CACHE, inline="always")
def _rk4(u, v, acc0, slope0, dt, buffers, force, im, k, c, keys, springs, walls, drag):
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
        power, closed, _ = _slopes(
            u_stage, v_stage, acc, force, im, k, c, keys, springs, walls, drag
        )
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


@numba.njit(cache=CACHE)
def _record(u, v, dissipated, model, links, particles, sample, outputs):
    """Writes sample ``sample``; returns False when the state is not finite.
    ``model`` = (masses, k, c, keys, walls, kind); ``links`` = (link indices, their
    columns in the record), ``particles`` likewise."""
    out_link, out_wall, out_velocity, out_energy, out_momentum = outputs
    masses, k, c, keys, walls, kind = model
    left, right, _, _ = _wall_terms(u, v, keys, walls)
    links, link_columns = links
    particles, particle_columns = particles
    for i in range(links.shape[0]):
        j = links[i]
        delta = u[j] - u[j + 1]
        if kind[j] == 1:
            out_link[sample, link_columns[i]] = k[j] * delta
        else:
            force = _hertz_force(k[j], c[j], delta, v[j] - v[j + 1])[1]
            out_link[sample, link_columns[i]] = force
    for i in range(particles.shape[0]):
        out_velocity[sample, particle_columns[i]] = v[particles[i]]
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


@numba.njit(cache=CACHE, inline="always")
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


@numba.njit(cache=CACHE, forceinline=True)
def _plain_step(
    x_u, x_v, x_acc, y_u, y_v, y_acc, work, slope, dt, im, k, c, keys, springs, walls, drag
):
    """One RK4 step from the state in x (slopes ``x_acc``, ``slope``) into y. Returns
    (dissipated energy, end slope, whether the number of closed contacts varied).

    The plain steps and the substeps: numba compiles it once, LLVM inlines it at every
    call (forceinline; inline="always" made numba type and lower each copy anew)."""
    buffers = (work[0], work[1], work[2], work[3], work[4], y_u, y_v)
    force = work[5]
    increment, varied = _rk4(
        x_u, x_v, x_acc, slope, dt, buffers, force, im, k, c, keys, springs, walls, drag
    )
    end = _slopes(y_u, y_v, y_acc, force, im, k, c, keys, springs, walls, drag)
    return increment, end, varied


def _integrate_one(u, v, params, dt, n_steps, record_every, links, particles, outputs):
    """RK4 for one launch of the whole chain; ``u`` and ``v`` end as the final state.
    Returns the status, the step at which it was set, and the number of steps refined
    at contact events.

    Plain Python around the compiled step loop: as a numba entry point of its own, it
    would lower and optimise the whole loop a second time (~3 s of each cold compile).
    Its ints and floats reach the loop as int64 and float64, as chain.physics.at_rest's
    do, so numba compiles the loop once per kind of model."""
    links = (links, np.arange(links.shape[0]))
    particles = (particles, np.arange(particles.shape[0]))
    status, step, refined, _, _, _ = _integrate_part(
        u, v, params, dt, 0, n_steps, record_every, links, particles, outputs, 0, 0, 0.0, -1
    )
    return status, step, refined


@numba.njit(cache=CACHE, inline="always")
def _reached(u, v, gap, spread):
    """Whether a step that spread a disturbance by ``spread`` beads or fewer brought it
    into the QUIET_MARGIN beads at rest on either side of bead ``gap`` (see
    :mod:`chain.physics.at_rest`): only the beads it could have reached are looked at."""
    n = u.shape[0]
    for p in range(max(gap - QUIET_MARGIN, 0), max(gap - QUIET_MARGIN + spread, 0)):
        if u[p] != 0.0 or v[p] != 0.0:
            return True
    for p in range(min(gap + QUIET_MARGIN - spread, n), min(gap + QUIET_MARGIN, n)):
        if u[p] != 0.0 or v[p] != 0.0:
            return True
    return False


@numba.njit(cache=CACHE, inline="always")
def _hand_back(in_y, x_u, x_v, y_u, y_v, u, v, status):
    """The state reached (in y or in x) into (u, v); returns the status, set to
    _NOT_FINITE if it was _OK and the state is not finite."""
    if in_y:
        _copy_into(x_u, y_u)
        _copy_into(x_v, y_v)
    if status == _OK and not (_all_finite(x_u) and _all_finite(x_v)):
        status = _NOT_FINITE
    _copy_into(u, x_u)
    _copy_into(v, x_v)
    return status


@numba.njit(cache=CACHE, inline="always")
def _work_buffers(n):
    """Five RK4 buffers and the link forces."""
    return (
        np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(max(n - 1, 1))
    )  # fmt: skip


# A refined step is EVENT_SUBSTEPS plain steps of dt / EVENT_SUBSTEPS through the same
# inlined step, at two call sites, one per order of the arrays, so that the loop never
# swaps array variables (a swap costs reference-count updates). One function, 62 lines:
# split into named steps it gives the same bits but compiles ~1.8 s longer per kind of
# model and runs ~2.5 % slower with Kuwabara-Kono (benchmarks/kernel_breakdown.py --split).
@compile_once.shared
@numba.njit(cache=CACHE, nogil=True)
def _integrate_part(
    u, v, params, dt, step, n_steps, record_every, links, particles, outputs,
    refine, refined, dissipated, gap,
):  # fmt: skip
    """RK4 for one launch from step ``step`` (sample 0 is recorded at step 0) to
    ``n_steps``, or until a disturbance comes within QUIET_MARGIN beads of bead ``gap``
    (-1: never), whose left neighbour stands for skipped beads at rest; ``u`` and
    ``v`` end as the state reached. ``links`` and ``particles``: (indices, record
    columns). Returns (status, step reached, refined steps, refine, dissipated energy
    J, whether the margin was reached)."""
    im, masses, k, damping, keys, springs, walls, drag, kind, c = params
    # Unpacked once: a tuple holding None gives wrong elements inside some callees.
    recorded = (masses, k, damping, keys, walls, kind)
    n = u.shape[0]
    work = _work_buffers(n)
    x_u, x_v, x_acc = u.copy(), v.copy(), np.empty(n)
    y_u, y_v, y_acc = np.empty(n), np.empty(n), np.empty(n)
    slope = _slopes(x_u, x_v, x_acc, work[5], im, k, c, keys, springs, walls, drag)
    if step == 0:  # sample 0, as int64: a literal 0 compiled _record a second time
        _record(x_u, x_v, dissipated, recorded, links, particles, step, outputs)
    status = _OK
    in_y = False  # the state is in (y_u, y_v, y_acc), else in (x_u, x_v, x_acc)
    reached = False
    while step < n_steps and status == _OK and not reached:
        target = min(n_steps, (step // record_every + 1) * record_every)
        while step < target and not reached:
            # A plain step, or the step redone in EVENT_SUBSTEPS substeps: the same RK4
            # step, from x into y or back (an even count of substeps ends where it began).
            substeps = 1 if refine == 0 else EVENT_SUBSTEPS
            h = dt / substeps
            increment = 0.0  # 0.0 + x is x here: dissipated is never -0.0 (same bits)
            varied = False
            end = slope
            for _ in range(substeps):
                if in_y:
                    part, end, changed = _plain_step(
                        y_u, y_v, y_acc, x_u, x_v, x_acc, work, end, h,
                        im, k, c, keys, springs, walls, drag,
                    )  # fmt: skip
                else:
                    part, end, changed = _plain_step(
                        x_u, x_v, x_acc, y_u, y_v, y_acc, work, end, h,
                        im, k, c, keys, springs, walls, drag,
                    )  # fmt: skip
                increment += part
                varied = varied or changed
                in_y = not in_y
            event = varied or end[2] != slope[2]
            if refine == 0:
                if event:  # redone in substeps below
                    in_y = not in_y  # the state is where it was
                    refine = EVENT_AFTERMATH + 1
                    continue
            else:
                refine = EVENT_AFTERMATH if event else refine - 1
                refined += 1
            step += 1
            dissipated += increment
            slope = end
            if gap >= 0:  # (tested here: inside the helper it cost 5 %)
                spread = 4 * substeps  # beads a (sub)step moves a disturbance by, at most
                if in_y:
                    reached = _reached(y_u, y_v, gap, spread)
                else:
                    reached = _reached(x_u, x_v, gap, spread)
        if step % record_every == 0 and step == target:
            sample = step // record_every
            # Written out: as a helper taking the state's place, the kernel ran 4 % slower.
            if in_y:
                finite = _record(y_u, y_v, dissipated, recorded, links, particles, sample, outputs)
            else:
                finite = _record(x_u, x_v, dissipated, recorded, links, particles, sample, outputs)
            if not finite:
                status = _NOT_FINITE
    status = _hand_back(in_y, x_u, x_v, y_u, y_v, u, v, status)
    return status, step, refined, refine, dissipated, reached


# numba's cache does not see edits of slopes.py, which these kernels inline: checked
# here, before any of them runs (chain.physics.kernel_cache).
kernel_cache.forget_if_sources_changed(__name__, globals())
