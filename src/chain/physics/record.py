"""What a simulation records: every contact and bead of a short chain, an overview of
a long one, or a stated selection; and the warning when a record grows past 1 GB.

:func:`chain.physics.simulation.simulate` records, per launch, samples x (contacts +
bead velocities) x 8 bytes; this module decides which contacts and beads unless the
caller says, and turns the numbers a person reads (contacts 1..N-1, beads 1..N) into
the links and particles the integrator records.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from chain.errors import ParameterError
from chain.physics.model import ChainModel

#: Chains with more contacts than this record by default an overview, not every contact:
#: every stride-th contact and bead with stride = ceil((N - 1) / OVERVIEW_CONTACTS), the
#: last ones, and the contacts and beads of the sensors (see :func:`default_record`).
OVERVIEW_CONTACTS = 500

#: A record larger than this (bytes, all launches) warns (:class:`LargeRecordWarning`).
RECORD_WARNING_BYTES = 1e9

#: ``contacts=ALL`` / ``beads=ALL``: record every contact / bead, whatever the chain.
ALL = "all"


class LargeRecordWarning(UserWarning):
    """A simulation was asked to record more than :data:`RECORD_WARNING_BYTES`."""


def felt_contacts(model: ChainModel, beads) -> tuple[int, ...]:
    """The contacts whose forces :meth:`SimulationResult.force_felt` reads for ``beads``:
    k = n-1 and n for bead n (an end bead's outer side is the end force, always kept).

    Pass them as ``simulate(..., contacts=...)`` to record only what a readout needs.

    Parameters
    ----------
    model : ChainModel
        The chain.
    beads : sequence of int
        Bead numbers n, 1..N.
    """
    n_beads = model.n_beads
    wanted = {k for n in beads for k in (int(n) - 1, int(n)) if 1 <= k <= n_beads - 1}
    return tuple(sorted(wanted))


def default_record(model: ChainModel) -> tuple[tuple[int, ...] | None, tuple[int, ...] | None]:
    """The contacts and beads :func:`simulate` records by default, as its ``contacts``
    and ``beads``: (None, None), every one, for a chain of up to
    :data:`OVERVIEW_CONTACTS` contacts; for a longer one contacts 1, 1 + s, 1 + 2 s, ...,
    N - 1 and beads 1, 1 + s, ..., N with the stride s = ceil((N - 1) /
    OVERVIEW_CONTACTS), and the sensor beads with their contacts (so that
    :meth:`SimulationResult.force_felt` reads every sensor bead).

    Parameters
    ----------
    model : ChainModel
        The chain.
    """
    n_beads = model.n_beads
    if n_beads - 1 <= OVERVIEW_CONTACTS:
        return None, None
    stride = math.ceil((n_beads - 1) / OVERVIEW_CONTACTS)
    sensors = model.sensor_beads
    contacts = {*range(1, n_beads, stride), n_beads - 1, *felt_contacts(model, sensors)}
    beads = {*range(1, n_beads + 1, stride), n_beads, *sensors}
    return tuple(sorted(contacts)), tuple(sorted(beads))


def recorded(model: ChainModel, contacts, beads):
    """(contacts, beads) to record: sorted numbers, or None for every one."""
    default_contacts, default_beads = default_record(model)
    contacts = (
        default_contacts if contacts is None else _numbers("contacts", contacts, model.n_beads - 1)
    )
    beads = default_beads if beads is None else _numbers("beads", beads, model.n_beads)
    return contacts, beads


def warn_if_large(model: ChainModel, n_launches: int, n_samples: int, contacts, beads) -> None:
    """:class:`LargeRecordWarning` when the record passes :data:`RECORD_WARNING_BYTES`."""
    n_contacts = model.n_beads - 1 if contacts is None else len(contacts)
    n_beads = model.n_beads if beads is None else len(beads)
    # Bead velocities are held twice: per particle, then per bead.
    size = 8.0 * n_launches * n_samples * (n_contacts + 2 * n_beads)
    if size <= RECORD_WARNING_BYTES:
        return
    warnings.warn(
        f"simulate: the record of {n_contacts} contact forces and {n_beads} bead velocities, "
        f"{n_samples} samples x {n_launches} launches, takes {size / 1e9:.1f} GB. Record "
        "less: contacts=felt_contacts(model, beads) or range(1, N, stride) for a selection, "
        "beads=() for no velocities, a longer record_interval, or fewer launches per call "
        f"(the default records an overview of chains longer than {OVERVIEW_CONTACTS} "
        "contacts).",
        LargeRecordWarning,
        stacklevel=4,
    )


def _numbers(name: str, values, largest: int) -> tuple[int, ...] | None:
    """Sorted distinct numbers 1..largest, or None for all (``"all"``)."""
    if isinstance(values, str):
        if values != ALL:
            raise ParameterError(f"{name} must be numbers or {ALL!r}, got {values!r}")
        return None
    numbers = sorted({int(x) for x in np.atleast_1d(np.asarray(values, dtype=np.int64))})
    if numbers and not (1 <= numbers[0] and numbers[-1] <= largest):
        raise ParameterError(f"{name} must lie in 1..{largest}, got {values!r}")
    return tuple(numbers)


def links_to_record(model: ChainModel, contacts) -> np.ndarray | None:
    if contacts is None:
        return None
    ends = [j for j in (model.left_striker, model.right_striker - 1) if j >= 0]
    chosen = [model.contact_link[k - 1] for k in contacts]
    return np.unique(np.r_[chosen, model.sensor_link, ends].astype(np.int64))


def particles_to_record(model: ChainModel, beads) -> np.ndarray | None:
    if beads is None:
        return None
    chosen = [np.arange(model.bead_first[b - 1], model.bead_last[b - 1] + 1) for b in beads]
    return np.concatenate([np.zeros(0, dtype=np.int64), *chosen]).astype(np.int64)
