"""Simulate a chain and read the result bead by bead (beads 1..N, contacts 1..N-1).

>>> from chain import uniform_chain, simulate
>>> result = simulate(uniform_chain(25), v_left=0.1, v_right=0.1, duration=1.5e-3)
>>> result.time            # (S,) s
>>> result.force_felt(9)   # (B, S) N, (F_{8,9} + F_{9,10}) / 2 as in the paper's Fig. 3
"""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from chain.errors import ParameterError, require_positive
from chain.physics.integrator import (
    DEFAULT_MAX_ENERGY_DRIFT,
    RawTrajectory,
    integrate,
    integrate_many,
)
from chain.physics.model import ChainModel, launch_velocities
from chain.physics.record import (
    ALL,
    OVERVIEW_CONTACTS,
    RECORD_WARNING_BYTES,
    LargeRecordWarning,
    default_record,
    felt_contacts,
    links_to_record,
    particles_to_record,
    recorded,
    warn_if_large,
)
from chain.physics.time_step import (
    STEPS_PER_CONTACT_TIME,
    STEPS_PER_SPRING_PERIOD,
    default_time_step,
)

#: Default recording interval, s.
DEFAULT_RECORD_INTERVAL = 1e-6


@dataclass(frozen=True)
class SimulationResult:
    """A batch of simulated launches of one chain, indexed the way a person reads it.

    Attributes
    ----------
    model : ChainModel
    time : (S,) s
    v_left, v_right : (B,) launch speeds, m/s
    contact_force : (B, S, K) N; the recorded contacts (all N-1 of a short chain by
        default: contact k, joining beads k and k+1, at index k-1); see :attr:`contacts`
    end_force : (B, S, 2) N; force on bead 1 from its left (wall or striker) and on bead
        N from its right; zero for a free end
    bead_velocity : (B, S, Q) m/s; centre-of-mass velocity of each recorded bead (all N
        of a short chain by default); see :attr:`beads`
    sensor_force : (B, S, n_sensors) N; sensor-spring readings k_s * compression
    kinetic_energy, potential_energy, dissipated_energy : (B, S) J
    momentum : (B, S) kg m/s (all particles, strikers included)
    dt : s, the integration step
    contacts, beads : tuple of int or None
        Contact and bead numbers recorded, in column order, when not all were (a
        selection, or the overview of a long chain: :func:`default_record`); None when
        all were recorded.
    """

    model: ChainModel
    time: np.ndarray
    v_left: np.ndarray
    v_right: np.ndarray
    contact_force: np.ndarray
    end_force: np.ndarray
    bead_velocity: np.ndarray
    sensor_force: np.ndarray
    kinetic_energy: np.ndarray
    potential_energy: np.ndarray
    dissipated_energy: np.ndarray
    momentum: np.ndarray
    dt: float
    contacts: tuple[int, ...] | None = None
    beads: tuple[int, ...] | None = None

    @property
    def total_energy(self) -> np.ndarray:
        """E_kin + E_pot + E_diss, (B, S) J; constant up to integration error."""
        return self.kinetic_energy + self.potential_energy + self.dissipated_energy

    @property
    def energy_drift(self) -> np.ndarray:
        """Largest relative change of :attr:`total_energy` per launch, (B,)."""
        total = self.total_energy
        return np.max(np.abs(total - total[:, :1]), axis=1) / np.abs(total[:, 0])

    def contact(self, k: int) -> np.ndarray:
        """Force of contact k (beads k and k+1), (B, S) N."""
        if not isinstance(k, int | np.integer) or not 1 <= k <= self.model.n_beads - 1:
            raise ParameterError(f"contact must be in 1..{self.model.n_beads - 1}, got {k!r}")
        return self.contact_force[:, :, _column(self.contacts, int(k), "contact", "contacts")]

    def force_felt(self, bead: int) -> np.ndarray:
        """Force "felt by" bead n, (F_{n-1,n} + F_{n,n+1}) / 2, (B, S) N.

        What a piezo inside a bead cut in two reads when the sensor is not modelled
        (the paper's Fig. 3). At an end the missing contact is the wall or striker
        force (zero for a free end).
        """
        index = self.model.bead_index(bead)
        n = self.model.n_beads
        left = self.end_force[:, :, 0] if index == 0 else self.contact(index)
        right = self.end_force[:, :, 1] if index == n - 1 else self.contact(index + 1)
        return 0.5 * (left + right)

    def sensor(self, bead: int) -> np.ndarray:
        """Reading of the split sensor bead ``bead``, k_s times its compression, (B, S) N."""
        if bead not in self.model.sensor_beads:
            raise ParameterError(
                f"bead {bead} is not a sensor bead; sensor beads: {list(self.model.sensor_beads)}"
            )
        return self.sensor_force[:, :, self.model.sensor_beads.index(bead)]

    def velocity(self, bead: int) -> np.ndarray:
        """Velocity of bead n, (B, S) m/s."""
        self.model.bead_index(bead)
        return self.bead_velocity[:, :, _column(self.beads, int(bead), "bead", "beads")]


def _column(recorded, number: int, what: str, keyword: str) -> int:
    """Column of ``number`` (1-based) in a record of ``recorded`` numbers (None: all)."""
    if recorded is None:
        return number - 1
    if number not in recorded:
        raise ParameterError(
            f"{what} {number} was not recorded; pass {keyword}= including it to simulate "
            f"(recorded: {list(recorded)})"
        )
    return recorded.index(number)


def simulate(
    model: ChainModel,
    v_left,
    v_right=0.0,
    duration: float = 2.6e-3,
    dt: float | None = None,
    record_interval: float = DEFAULT_RECORD_INTERVAL,
    max_energy_drift: float = DEFAULT_MAX_ENERGY_DRIFT,
    initial_displacement=None,
    *,
    contacts=None,
    beads=None,
) -> SimulationResult:
    """Launch waves from both ends of ``model`` (a batch of launches) and integrate.

    Parameters
    ----------
    model : ChainModel
        The chain (see :func:`chain.physics.builders.uniform_chain`).
    v_left : float or array of B floats
        Speed given to bead 1 (or the left striker), moving right, m/s.
    v_right : float or array of B floats
        Speed given to bead N (or the right striker), moving left, m/s; 0 for a
        reference (single-wave) run.
    duration : float
        Simulated time, s.
    dt : float, optional
        RK4 time step, s; default :func:`default_time_step` at the fastest launch,
        shortened so that ``record_interval`` is a whole number of steps.
    record_interval : float
        Time between recorded samples, s; with an explicit ``dt`` it is rounded to a
        whole number of steps.
    max_energy_drift : float
        Raise :class:`~chain.physics.integrator.IntegrationError` above this relative drift.
    initial_displacement : array (B, P) or (P,), optional
        Particle displacements at t = 0, m (default 0: all particles just touching).
        A positive value on the right striker (or negative on the left one) is an
        initial gap, which delays that launch by gap / speed.
    contacts : sequence of int or "all", optional
        Contacts (1..N-1) whose force is recorded. Default: every contact for a chain
        of up to :data:`OVERVIEW_CONTACTS` contacts, an overview for a longer one (every
        stride-th contact and the sensors', :func:`default_record`). ``"all"``
        (:data:`ALL`) records every contact of any chain: N x samples x 8 bytes per
        launch. Sensor springs, strikers, walls, energies and momentum are always
        recorded. A record over :data:`RECORD_WARNING_BYTES` warns
        (:class:`LargeRecordWarning`) and says how to record less.
    beads : sequence of int or "all", optional
        Beads (1..N) whose velocity is recorded; default as for ``contacts`` (every
        bead, or every stride-th bead and the sensor beads); ``()`` for none.
    """
    arguments, view = _request(
        model,
        v_left,
        v_right,
        duration,
        dt,
        record_interval,
        max_energy_drift,
        initial_displacement,
        contacts,
        beads,
    )
    return view(integrate(**arguments))


def simulate_many(runs: Sequence[Mapping], threads: int | None = None, **common) -> list:
    """Simulate many batches (chains, speeds) at once on all cores (a sweep): one
    SimulationResult per run, in order.

    Every launch of every run is one task of one thread pool, longest first (see
    :func:`chain.physics.integrator.integrate_many`), so that a sweep of many small
    chains keeps every core busy and pays no Python between launches. Each result is
    bit-identical to :func:`simulate` with the same arguments.

    Parameters
    ----------
    runs : sequence of mappings
        Arguments of :func:`simulate` per run (``model`` and ``v_left`` at least; m/s,
        s as there).
    threads : int, optional
        Threads of the pool; default numba's thread count.
    **common
        Arguments of :func:`simulate` shared by every run (a run's own win), e.g.
        ``duration=2e-3, contacts=()``.
    """
    requests = [_request(**_simulate_arguments({**common, **run})) for run in runs]
    raws = integrate_many([arguments for arguments, _ in requests], threads)
    return [view(raw) for (_, view), raw in zip(requests, raws, strict=True)]


def _simulate_arguments(arguments: Mapping) -> dict:
    """``arguments`` of :func:`simulate` completed with its defaults, checked by name."""
    names = inspect.signature(simulate).parameters
    unknown = sorted(set(arguments) - set(names))
    if unknown:
        raise ParameterError(f"simulate_many: unknown arguments {unknown}; known: {list(names)}")
    defaults = {
        name: parameter.default
        for name, parameter in names.items()
        if parameter.default is not inspect.Parameter.empty
    }
    return {**defaults, **arguments}


def _request(
    model,
    v_left,
    v_right,
    duration,
    dt,
    record_interval,
    max_energy_drift,
    initial_displacement,
    contacts,
    beads,
):
    """(keyword arguments of integrate, function that reads its RawTrajectory by bead)
    for :func:`simulate`'s arguments, checked."""
    velocities = launch_velocities(model, v_left, v_right)
    left = np.atleast_1d(np.asarray(v_left, dtype=float))
    right = np.atleast_1d(np.asarray(v_right, dtype=float))
    left, right = np.broadcast_arrays(left, right)
    fastest = float(max(left.max(), right.max()))
    if fastest <= 0:
        raise ParameterError("v_left or v_right must be > 0 m/s in at least one launch")
    record_interval = require_positive("record_interval", record_interval)
    if dt is None:
        # Shrink the default step so that samples fall exactly every record_interval.
        dt = record_interval / math.ceil(record_interval / default_time_step(model, fastest))
    dt = require_positive("dt", dt)
    record_every = max(1, round(record_interval / dt))
    contacts, beads = recorded(model, contacts, beads)
    duration = require_positive("duration", duration)
    n_samples = math.ceil(duration / dt - 1e-9) // record_every + 1
    warn_if_large(model, left.size, n_samples, contacts, beads)
    arguments = dict(
        model=model,
        initial_velocity=velocities,
        duration=duration,
        dt=dt,
        record_every=record_every,
        initial_displacement=initial_displacement,
        max_energy_drift=max_energy_drift,
        links=links_to_record(model, contacts),
        particles=particles_to_record(model, beads),
    )
    left, right = left.copy(), right.copy()
    return arguments, lambda raw: _bead_view(model, raw, left, right, contacts, beads)


def _bead_view(
    model: ChainModel, raw: RawTrajectory, left, right, contacts, beads
) -> SimulationResult:
    link_column = np.full(model.n_particles - 1, -1, dtype=np.int64)
    link_column[raw.links] = np.arange(len(raw.links))
    contact_links = (
        model.contact_link
        if contacts is None
        else model.contact_link[np.asarray(contacts, dtype=np.int64) - 1]
    )
    end_force = raw.wall_force.copy()
    if model.left_striker >= 0:
        end_force[:, :, 0] = raw.link_force[:, :, link_column[model.left_striker]]
    if model.right_striker >= 0:
        end_force[:, :, 1] = raw.link_force[:, :, link_column[model.right_striker - 1]]
    return SimulationResult(
        model=model,
        time=raw.time,
        v_left=left,
        v_right=right,
        contact_force=_columns(raw.link_force, link_column[contact_links]),
        end_force=end_force,
        bead_velocity=_bead_velocity(model, raw, beads),
        sensor_force=_columns(raw.link_force, link_column[model.sensor_link]),
        kinetic_energy=raw.energy[:, :, 0],
        potential_energy=raw.energy[:, :, 1],
        dissipated_energy=raw.energy[:, :, 2],
        momentum=raw.momentum,
        dt=raw.dt,
        contacts=contacts,
        beads=beads,
    )


def _columns(record: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """``record[:, :, columns]``; the record itself when that is every column in order
    (a long chain's record is not copied)."""
    if columns.size == record.shape[2] and np.array_equal(columns, np.arange(columns.size)):
        return record
    return record[:, :, columns]


def _bead_velocity(model: ChainModel, raw: RawTrajectory, beads) -> np.ndarray:
    """Mass-weighted mean velocity of each recorded bead, (B, S, Q) m/s, computed with
    the same reductions as a per-bead loop (so the bits do not depend on N)."""
    numbers = np.arange(model.n_beads) if beads is None else np.asarray(beads, dtype=int) - 1
    column = np.full(model.n_particles, -1, dtype=np.int64)
    column[raw.particles] = np.arange(len(raw.particles))
    masses = model.masses
    first, last = model.bead_first[numbers], model.bead_last[numbers]
    single = np.flatnonzero(first == last)
    if single.size == numbers.size:
        # Whole-array operations, the bits of the loop's (0.0 + v m) / m.
        weight = masses[first]
        velocity = _columns(raw.velocity, column[first]) * weight
        velocity += 0.0
        velocity /= weight
        return velocity
    velocity = np.empty((*raw.velocity.shape[:2], len(numbers)))
    weighted = raw.velocity[:, :, column[first[single]]] * masses[first[single]]
    velocity[:, :, single] = weighted[..., None].sum(axis=3) / masses[first[single]]
    for i in np.flatnonzero(first != last):
        a, b = first[i], last[i]
        part = raw.velocity[:, :, column[a : b + 1]] * masses[a : b + 1]
        velocity[:, :, i] = part.sum(axis=2) / masses[a : b + 1].sum()
    return velocity


__all__ = [
    "ALL",
    "DEFAULT_RECORD_INTERVAL",
    "OVERVIEW_CONTACTS",
    "RECORD_WARNING_BYTES",
    "STEPS_PER_CONTACT_TIME",
    "STEPS_PER_SPRING_PERIOD",
    "LargeRecordWarning",
    "SimulationResult",
    "default_record",
    "default_time_step",
    "felt_contacts",
    "simulate",
    "simulate_many",
]
