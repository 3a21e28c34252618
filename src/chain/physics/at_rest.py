"""Skipping the beads a wave has not reached yet.

A bead exactly at rest (u = v = 0) between neighbours at rest feels no force: its Hertz
contacts are open (delta = 0) and a sensor spring is unstretched. RK4 leaves it exactly
at rest until a disturbance arrives, and every sum it enters (forces, energies,
momentum, the contact count and fingerprint) gets +0.0 from it. So a launch may skip
the middle of the longest run of such beads and give the same bits: the kernel
integrates a shorter chain in which one link, of zero force, stands for the skipped
beads, and stops when a disturbance comes within
:data:`~chain.physics.kernels.QUIET_MARGIN` beads of them; the skipped part then
shrinks, and is dropped when it is short. A collision in a long chain costs what the
beads the waves have reached cost: 10,000 beads x 5 ms in the paper's collision
integrate a few hundred.
"""

from __future__ import annotations

import numpy as np

from chain.physics.kernels import _OK, QUIET_MARGIN, _integrate_one, _integrate_part
from chain.physics.model import SPRING

#: Beads at rest kept on each side of the skipped ones when the skipped part is laid
#: out: twice the kernel's margin, so that a part runs until a disturbance has
#: travelled QUIET_MARGIN beads.
SLACK = 2 * QUIET_MARGIN

#: Fewest beads worth skipping (fewer: the whole chain is integrated).
MIN_SKIPPED = QUIET_MARGIN


def quiet_span(u: np.ndarray, v: np.ndarray) -> tuple[int, int] | None:
    """The beads q0..q1-1 a run may skip, or None.

    Parameters
    ----------
    u, v : (P,) arrays
        Displacements, m, and velocities, m/s, of the particles.

    Returns
    -------
    (q0, q1) or None
        The middle of the longest run of particles exactly at rest (+0.0: a -0.0
        would be recorded as such by the whole-chain run), less :data:`SLACK` at each
        end; None when that leaves fewer than :data:`MIN_SKIPPED`.
    """
    if u.shape[0] < 2 * SLACK + MIN_SKIPPED:  # the paper's chains: nothing to skip
        return None
    rest = (u == 0.0) & (v == 0.0) & ~np.signbit(u) & ~np.signbit(v)
    # Boundaries of the runs of True in rest: starts and ends, paired.
    edges = np.flatnonzero(np.diff(np.r_[0, rest.astype(np.int8), 0]))
    if edges.size == 0:
        return None
    starts, ends = edges[0::2], edges[1::2]
    longest = int(np.argmax(ends - starts))
    q0, q1 = int(starts[longest]) + SLACK, int(ends[longest]) - SLACK
    return (q0, q1) if q1 - q0 >= MIN_SKIPPED else None


def _shrunk(u: np.ndarray, v: np.ndarray, span: tuple[int, int]) -> tuple[int, int] | None:
    """``span`` after a disturbance came near it: :data:`SLACK` beads at rest again
    between it and the nearest moving bead on each side (None when too short)."""
    q0, q1 = span
    moving = (u != 0.0) | (v != 0.0)
    left = np.flatnonzero(moving[:q0])
    right = np.flatnonzero(moving[q1:])
    if left.size:
        q0 = max(q0, int(left[-1]) + 1 + SLACK)
    if right.size:
        q1 = min(q1, q1 + int(right[0]) - SLACK)
    return (q0, q1) if q1 - q0 >= MIN_SKIPPED else None


def _compact_params(params: tuple, span: tuple[int, int]) -> tuple:
    """The kernel's model arrays of the chain without beads q0..q1-1: link q0-1 of the
    short chain (zero force) joins bead q0-1 to bead q1."""
    q0, q1 = span
    im, masses, k, damping, keys, _, walls, drag, kind, c = params
    n = im.shape[0]
    beads = np.r_[0:q0, q1:n]
    links = np.r_[0:q0, q1 : n - 1]
    short_kind = kind[links]
    springs = np.r_[np.flatnonzero(short_kind == SPRING), links.size].astype(np.int64)
    return (
        im[beads],
        masses[beads],
        k[links],
        damping[links],
        np.r_[keys[links], keys[-2:]],  # the fingerprint's keys, walls last
        springs,
        walls,
        None if drag is None else np.ascontiguousarray(drag[beads]),
        short_kind,
        None if c is None else c[links],
    )


def _compact_record(indices: np.ndarray, span: tuple[int, int], first_skipped: int):
    """(indices in the short chain, record columns) of the recorded ``indices`` that it
    holds: those below ``first_skipped`` and from q1 on. The others are at rest or of
    zero force: their columns keep the record's zeros."""
    q0, q1 = span
    columns = np.flatnonzero((indices < first_skipped) | (indices >= q1))
    kept = indices[columns]
    return np.where(kept >= q1, kept - (q1 - q0), kept), columns


def integrate_launch(u, v, params, dt, n_steps, record_every, links, particles, outputs):
    """RK4 for one launch, skipping beads at rest; the arguments and the result are
    those of :func:`chain.physics.kernels._integrate_one` (same bits).

    Parameters
    ----------
    u, v : (P,) arrays
        Initial displacements, m, and velocities, m/s; they end as the final state.
    params : tuple
        The kernel's model arrays (:func:`chain.physics.launches._lean_params`).
    dt : float
        Step, s.
    n_steps, record_every : int
        Steps, and steps between records.
    links, particles : int64 arrays
        Recorded link and particle indices.
    outputs : tuple of arrays
        The launch's zeroed records.
    """
    span = quiet_span(u, v)
    if span is None:
        return _integrate_one(u, v, params, dt, n_steps, record_every, links, particles, outputs)
    step = refine = refined = 0
    dissipated = 0.0
    while span is not None:
        q0, q1 = span
        beads = np.r_[0:q0, q1 : u.shape[0]]
        short_u, short_v = u[beads], v[beads]
        record = (_compact_record(links, span, q0 - 1), _compact_record(particles, span, q0))
        status, step, refined, refine, dissipated, reached = _integrate_part(
            short_u, short_v, _compact_params(params, span), dt, step, n_steps,
            record_every, *record, outputs, refine, refined, dissipated, q0,
        )  # fmt: skip
        u[beads], v[beads] = short_u, short_v
        if status != _OK or not reached:
            return status, step, refined
        span = _shrunk(u, v, span)
    whole = ((links, np.arange(links.size)), (particles, np.arange(particles.size)))
    status, step, refined, *_ = _integrate_part(
        u, v, params, dt, step, n_steps, record_every, *whole, outputs,
        refine, refined, dissipated, -1,
    )  # fmt: skip
    return status, step, refined
