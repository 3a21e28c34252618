"""Fixed-step classical RK4 for a :class:`~chain.physics.model.ChainModel` (the paper's method).

The private numba kernels take flat arrays and write into preallocated outputs;
:func:`integrate` checks its inputs, allocates, and turns a failed run into an
:class:`IntegrationError`. The state integrated per launch is (u, v, E_diss): the
dissipated energy is integrated with the same RK4 so that
E_kin + E_pot + E_diss is conserved to the scheme's accuracy with or without
dissipation, which makes the energy drift a check on the step in every run.
"""

from __future__ import annotations

import hashlib
import logging
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numba
import numpy as np

from chain.errors import ParameterError, require_int, require_positive
from chain.physics.kernels import _OK
from chain.physics.launches import _lean_launches, _reference_launches, _run_launches
from chain.physics.model import ChainModel

#: Names each launch it integrates (:func:`launch_digests`), so that a run's logs show
#: whether any launch was integrated twice.
log = logging.getLogger(__name__)

#: Default bound on the relative energy drift before a run is declared broken.
DEFAULT_MAX_ENERGY_DRIFT = 1e-6


class IntegrationError(RuntimeError):
    """The integration failed (blow-up or energy drift above threshold)."""


@dataclass(frozen=True)
class RawTrajectory:
    """Particle-level output of :func:`integrate`; :mod:`chain.physics.simulation` maps it to beads.

    Attributes
    ----------
    time : (S,) s
    link_force : (B, S, K) N, compression positive, of the recorded links ``links``
    wall_force : (B, S, 2) N, left and right wall contact forces
    velocity : (B, S, Q) m/s of the recorded particles ``particles``
    energy : (B, S, 3) J: kinetic, potential (Hertz + springs), dissipated so far
    momentum : (B, S) kg m/s
    final_displacement, final_velocity : (B, P) m, m/s
    dt : s, the step used
    refined_steps : (B,) steps integrated in EVENT_SUBSTEPS substeps (contact events)
    links : (K,) recorded link indices (all P-1 links by default)
    particles : (Q,) recorded particle indices (all P particles by default)
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
    links: np.ndarray | None = None
    particles: np.ndarray | None = None

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
    *,
    links=None,
    particles=None,
    kernel: str = "lean",
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
    links : sequence of int, optional
        Link indices (0..P-2) whose force is recorded; default all. Energies, momentum
        and wall forces are always recorded.
    particles : sequence of int, optional
        Particle indices (0..P-1) whose velocity is recorded; default all.
    kernel : {"lean", "reference"}
        "reference" runs the general kernel of :mod:`chain.physics.reference_kernel`
        (same results bit for bit, slower; for tests and benchmarks).
    """
    batch = _prepare(
        model,
        initial_velocity,
        duration,
        dt,
        record_every,
        initial_displacement,
        max_energy_drift,
        links,
        particles,
        kernel,
    )
    _run_launches(batch.launches, numba.get_num_threads())
    return _finish(batch)


def integrate_many(batches: Sequence[Mapping], threads: int | None = None) -> list[RawTrajectory]:
    """Integrate several batches (different chains, steps, durations) at once, one
    RawTrajectory per batch, in order: every launch of every batch is one task of one
    pool of ``threads`` threads, longest first, so that a sweep of many small chains
    keeps every core busy.

    Each launch gives the same bits as :func:`integrate` would (one launch runs on one
    thread, whatever the pool).

    Parameters
    ----------
    batches : sequence of mappings
        Keyword arguments of :func:`integrate`, one mapping per batch (``model``,
        ``initial_velocity``, ``duration``, ``dt`` required; ``kernel`` must be "lean").
    threads : int, optional
        Threads of the pool; default numba's thread count (all cores unless limited by
        ``NUMBA_NUM_THREADS`` or :func:`numba.set_num_threads`).
    """
    prepared = []
    for number, arguments in enumerate(batches):
        if arguments.get("kernel", "lean") != "lean":
            raise ParameterError(f"batch {number}: integrate_many runs the lean kernel only")
        prepared.append(_prepare(**{"record_every": 1, **arguments}))
    threads = numba.get_num_threads() if threads is None else require_int("threads", threads, 1)
    _run_launches([launch for batch in prepared for launch in batch.launches], threads)
    return [_finish(batch) for batch in prepared]


@dataclass
class _Batch:
    """A batch ready to run: its records, its report and one task per launch (cost in
    particle-steps, function)."""

    model: ChainModel
    run: tuple
    n_samples: int
    links: np.ndarray
    particles: np.ndarray
    max_energy_drift: float
    outputs: tuple | list
    report: tuple
    launches: list


def _prepare(
    model,
    initial_velocity,
    duration,
    dt,
    record_every=1,
    initial_displacement=None,
    max_energy_drift=DEFAULT_MAX_ENERGY_DRIFT,
    links=None,
    particles=None,
    kernel="lean",
) -> _Batch:
    """The checked inputs of :func:`integrate`, records allocated, launches not run."""
    duration, dt, record_every = _check_run(duration, dt, record_every, max_energy_drift)
    velocity, displacement = _initial_state(model, initial_velocity, initial_displacement)
    links = _index_array("links", links, model.n_particles - 1)
    particles = _index_array("particles", particles, model.n_particles)
    if kernel not in ("lean", "reference"):
        raise ParameterError(f"kernel must be 'lean' or 'reference', got {kernel!r}")
    n_steps = math.ceil(duration / dt - 1e-9)
    n_samples = n_steps // record_every + 1
    run = (displacement, velocity, dt, n_steps, record_every)
    digests = launch_digests(model, displacement, velocity, dt, n_steps)
    log.info("integrating %d launches: %s", len(digests), " ".join(digests))
    if kernel == "lean":
        outputs, report, launches = _lean_launches(model, run, n_samples, links, particles)
    else:
        outputs, report, launches = _reference_launches(model, run, n_samples, links, particles)
    return _Batch(
        model, run, n_samples, links, particles, max_energy_drift, outputs, report, launches
    )


def launch_digests(model: ChainModel, displacement, velocity, dt: float, n_steps: int):
    """A digest of each launch of a batch: of what its trajectory depends on (the chain's
    masses, links and walls, its initial state, the step and the number of steps);
    two launches with one digest are the same integration.

    Parameters
    ----------
    model : ChainModel
        The chain.
    displacement, velocity : (B, P) arrays
        Initial displacements (m) and velocities (m/s) of each launch.
    dt : float
        Time step, s.
    n_steps : int
        Steps integrated.
    """
    chain = hashlib.blake2b(f"{dt!r} {n_steps}".encode(), digest_size=8)
    for name in ("masses", "link_kind", "link_stiffness", "link_eta", "wall_stiffness",
                 "wall_eta", "drag_rate"):  # fmt: skip
        chain.update(np.ascontiguousarray(getattr(model, name)).tobytes())
    digests = []
    for x, v in zip(displacement, velocity, strict=True):
        launch = chain.copy()
        launch.update(np.ascontiguousarray(x).tobytes() + np.ascontiguousarray(v).tobytes())
        digests.append(launch.hexdigest())
    return digests


def _finish(batch: _Batch) -> RawTrajectory:
    """The trajectory of a batch whose launches ran; raises on a blow-up or a drift."""
    displacement, velocity, dt, _, record_every = batch.run
    _raise_on_blow_up(batch.report, dt)
    trajectory = RawTrajectory(
        np.arange(batch.n_samples) * (record_every * dt),
        *batch.outputs,
        final_displacement=displacement,
        final_velocity=velocity,
        dt=dt,
        refined_steps=batch.report[2],
        links=batch.links,
        particles=batch.particles,
    )
    _raise_on_drift(trajectory.energy_drift, batch.max_energy_drift, dt)
    return trajectory


def _check_run(duration, dt, record_every, max_energy_drift):
    duration = require_positive("duration", duration)
    dt = require_positive("dt", dt)
    if not isinstance(record_every, int | np.integer) or record_every < 1:
        raise ParameterError(f"record_every must be an integer >= 1, got {record_every!r}")
    if not (max_energy_drift > 0):
        raise ParameterError(f"max_energy_drift must be > 0, got {max_energy_drift!r}")
    return duration, dt, int(record_every)


def _initial_state(model: ChainModel, initial_velocity, initial_displacement):
    n_particles = model.n_particles
    velocity = _batch_array("initial_velocity", initial_velocity, n_particles)
    if initial_displacement is None:
        return velocity, np.zeros_like(velocity)
    displacement = _batch_array("initial_displacement", initial_displacement, n_particles)
    if displacement.shape != velocity.shape:
        raise ParameterError(
            "initial_displacement and initial_velocity must have the same shape, got "
            f"{displacement.shape} and {velocity.shape}"
        )
    return velocity, displacement


def _index_array(name: str, values, size: int) -> np.ndarray:
    """Indices 0..size-1 as an int64 array; ``None`` means all of them."""
    if values is None:
        return np.arange(size, dtype=np.int64)
    array = np.asarray(values)
    if array.size == 0:
        return np.zeros(0, dtype=np.int64)
    if array.ndim != 1 or not np.issubdtype(array.dtype, np.integer):
        raise ParameterError(f"{name} must be a sequence of integer indices, got {values!r}")
    if array.min() < 0 or array.max() >= size:
        raise ParameterError(f"{name} must lie in 0..{size - 1}, got {values!r}")
    return np.ascontiguousarray(array, dtype=np.int64)


def _raise_on_blow_up(report, dt: float) -> None:
    status, fail_step, _ = report
    if np.any(status != _OK):
        b = int(np.flatnonzero(status != _OK)[0])
        raise IntegrationError(
            f"integration blew up (non-finite state) in launch {b} by step {fail_step[b]} "
            f"(t = {fail_step[b] * dt:.3e} s) with dt = {dt:.3e} s: the time step is too "
            "large for this run; reduce dt"
        )


def _raise_on_drift(drift: np.ndarray, max_energy_drift: float, dt: float) -> None:
    if np.any(drift > max_energy_drift):
        b = int(np.argmax(drift))
        raise IntegrationError(
            f"relative energy drift {drift[b]:.2e} in launch {b} exceeds max_energy_drift = "
            f"{max_energy_drift:.1e} with dt = {dt:.3e} s: the time step is too large for "
            "this run; reduce dt"
        )


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


__all__ = [
    "DEFAULT_MAX_ENERGY_DRIFT",
    "IntegrationError",
    "RawTrajectory",
    "integrate",
    "integrate_many",
]
