"""The right-hand side of Eq. 1 for the lean kernel (:mod:`chain.physics.kernels`).

Accelerations of every particle from the Hertz contacts, the sensor springs, the walls
and the track friction, with what the kernel needs to see contact events: the
dissipated power, the number of closed contacts and a fingerprint of which they are.
Same floating-point operations, in the same order, as the general kernel
(:mod:`chain.physics.reference_kernel`); numba compiles one version per model, the
absent terms (``c``, ``walls``, ``drag`` None) left out.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import types
from numba.extending import overload

from chain.physics import safe_cache

#: numba's cache only in a folder no other account can write (chain.physics.safe_cache).
CACHE = safe_cache.allowed(__file__)


@numba.njit(cache=CACHE, inline="always")
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
# loop over the links (a loop over runs of Hertz links between the sensor springs is
# 2.5x slower). Their shared trailing arguments ``im, k, c, keys, springs, walls, drag``
# are the model (see _integrate_one); ``c``, ``walls`` and ``drag`` are None when the
# model has no such term. ``walls`` is four floats, (stiffness, damping) of the left
# then the right wall (zero stiffness: none). numba wraps a call of a compiled function
# that LLVM does not inline in updates of its array arguments' reference counts, which
# made walls and track friction cost 7x and 3x: so _walls takes the end beads' scalars,
# and the drag loop is written in its overload (which LLVM inlines).


@numba.njit(cache=CACHE)
def _walls(u_first, v_first, u_last, v_last, key_left, key_right, walls):
    """(left force N, right force N, dissipated power W, fingerprint) of the walls, from
    the end beads' displacements (m) and velocities (m/s) and the fingerprint keys of
    the two wall contacts; zeros for a wall of zero stiffness."""
    left_stiffness, left_damping, right_stiffness, right_damping = walls
    power = 0.0
    left = 0.0
    right = 0.0
    mark = np.uint64(0)
    if left_stiffness > 0.0:
        elastic, left = _hertz_force(left_stiffness, left_damping, -u_first, -v_first)
        power -= (left - elastic) * v_first
        if u_first < 0.0:
            mark ^= key_left
    if right_stiffness > 0.0:
        elastic, right = _hertz_force(right_stiffness, right_damping, u_last, v_last)
        power += (right - elastic) * v_last
        if u_last > 0.0:
            mark ^= key_right
    return left, right, power, mark


# Dispatch on None at compile time. Not inline="always": with numba 0.68 an inlined
# overload made _record silently skip its energy writes. LLVM inlines the small
# implementations below; _walls, called with scalars only, needs no reference counts.
def _wall_terms(u, v, keys, walls):
    """_walls, or zeros when ``walls`` is None (decided when numba compiles)."""


@overload(_wall_terms)
def _wall_terms_overload(u, v, keys, walls):
    if walls is types.none:
        return lambda u, v, keys, walls: (0.0, 0.0, 0.0, np.uint64(0))

    def terms(u, v, keys, walls):
        n, m = u.shape[0], keys.shape[0]  # the walls' keys last
        return _walls(u[0], v[0], u[n - 1], v[n - 1], keys[m - 2], keys[m - 1], walls)

    return terms


def _drag_terms(v, acc, drag, power):
    """Track friction into ``acc``; returns the power with its dissipation added."""


@overload(_drag_terms)
def _drag_terms_overload(v, acc, drag, power):
    if drag is types.none:
        return lambda v, acc, drag, power: power

    def drag_terms(v, acc, drag, power):
        # drag[p] = (drag rate, mass x drag rate): the general kernel's m * g * v * v.
        for p in range(v.shape[0]):
            acc[p] -= drag[p, 0] * v[p]
            power += drag[p, 1] * v[p] * v[p]
        return power

    return drag_terms


def _wall_energy(u, walls, energy):
    """``energy`` plus the elastic energy of the wall contacts, J."""


@overload(_wall_energy)
def _wall_energy_overload(u, walls, energy):
    if walls is types.none:
        return lambda u, walls, energy: energy
    return lambda u, walls, energy: _walls_energy(u[0], u[u.shape[0] - 1], walls, energy)


@numba.njit(cache=CACHE, inline="always")
def _slopes(u, v, acc, force, im, k, c, keys, springs, walls, drag):
    """Accelerations into ``acc``; returns (dissipated power, closed contacts, fingerprint).

    ``force`` (n - 1) is scratch for the link forces, N. ``springs`` lists the bonded
    links in order and ends with n - 1 (no link); ``c``, ``walls`` and ``drag`` are None
    when the model has no such term: numba then compiles a version without them (a
    branch on a flag made the loop 2x slower)."""
    n = u.shape[0]
    left, right, power, mark = _wall_terms(u, v, keys, walls)
    # Wall ends counted for free ends too, as the general kernel does.
    closed = 0
    if u[0] < 0.0:
        closed += 1
    if u[n - 1] > 0.0:
        closed += 1
    power, closed, mark = _link_terms(
        u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark
    )
    power = _drag_terms(v, acc, drag, power)
    return power, closed, mark


def _link_terms(u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark):
    """The links' accelerations into ``acc`` (end forces ``left``, ``right``, N); returns
    (power, closed, mark) with the links' dissipated power (W), closed contacts and
    fingerprint added: elastic links when ``c`` is None, else Kuwabara-Kono (decided
    when numba compiles)."""


# The overload's implementation is compiled anew for every set of compile flags of its
# callers (the step loop's differ from the step's), so it only hands over to a kernel
# compiled once.
@overload(_link_terms, jit_options={"forceinline": True})
def _link_terms_overload(
    u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark
):
    links = _elastic_links if c is types.none else _damped_links
    return lambda u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark: (
        links(u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark)
    )


@numba.njit(cache=CACHE, forceinline=True)
def _elastic_links(u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark):
    # In passes, so that the first has no branch and vectorises (SIMD: several links per
    # instruction): every link as a Hertz contact (an open one, delta <= 0, gives
    # k 0 sqrt(0) = 0), the bonded springs over them, then the accelerations. Same
    # floating-point operations in the same order as the general kernel (same bits).
    # The damped links stay one branchy loop: the same passes make them 1.3x slower.
    n = u.shape[0]
    for j in range(n - 1):
        delta = u[j] - u[j + 1]
        key = keys[j]
        if delta > 0.0:
            closed += 1
            mark ^= key
        else:
            delta = 0.0
        force[j] = k[j] * delta * math.sqrt(delta)
    for s in range(springs.shape[0] - 1):
        j = springs[s]
        delta = u[j] - u[j + 1]
        force[j] = k[j] * delta
        if delta > 0.0:  # counted above as a Hertz contact
            closed -= 1
            mark ^= keys[j]
    previous = left
    for j in range(n - 1):
        total = force[j]
        acc[j] = (previous - total) * im[j]
        previous = total
    acc[n - 1] = (previous - right) * im[n - 1]
    return power, closed, mark


@numba.njit(cache=CACHE, forceinline=True)
def _damped_links(u, v, acc, force, im, k, c, keys, springs, left, right, power, closed, mark):
    n = u.shape[0]
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
            rate = v[j] - v[j + 1]
            elastic, total = _hertz_force(k[j], c[j], delta, rate)
            power += (total - elastic) * rate
        acc[j] = (previous - total) * im[j]
        previous = total
    acc[n - 1] = (previous - right) * im[n - 1]
    return power, closed, mark


@numba.njit(cache=CACHE)
def _walls_energy(u_first, u_last, walls, energy):
    """``energy`` (J) plus the elastic energy of the wall contacts, from the end beads'
    displacements, m."""
    if walls[0] > 0.0 and u_first < 0.0:
        delta = -u_first
        energy += 0.4 * walls[0] * delta * delta * math.sqrt(delta)
    if walls[2] > 0.0 and u_last > 0.0:
        delta = u_last
        energy += 0.4 * walls[2] * delta * delta * math.sqrt(delta)
    return energy
