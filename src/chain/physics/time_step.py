"""The default RK4 time step: a fraction of the shortest contact time or spring period.

:func:`chain.physics.simulation.simulate` uses it when no step is given; the energy
drift that every run checks is what it is chosen against.
"""

from __future__ import annotations

import math

import numpy as np

from chain.errors import require_positive
from chain.physics.model import HERTZ, SPRING, ChainModel
from chain.physics.theory import hertz_contact_time

#: Steps per shortest two-body contact time in the default time step. The exact
#: Hertz scaling makes the energy drift a function of dt / t_c only; 1000 keeps the
#: conservative drift of the paper's N = 26 chain near 3e-10 over 2.6 ms at any launch
#: speed (RK4's own truncation error; the steps where a contact opens or closes are
#: refined by the integrator, see chain.physics.kernels.EVENT_SUBSTEPS).
STEPS_PER_CONTACT_TIME = 1000

#: Steps per period of the stiffest bonded spring (sensor beads) in the default step.
STEPS_PER_SPRING_PERIOD = 400


def default_time_step(model: ChainModel, max_launch_speed: float) -> float:
    """A time step that keeps the conservative energy drift near 1e-9 or below, s.

    The shortest Hertz contact time of any linked pair at a relative speed of twice
    the fastest launch (a head-on collision), divided by
    :data:`STEPS_PER_CONTACT_TIME`, and the shortest bonded-spring period divided by
    :data:`STEPS_PER_SPRING_PERIOD`, whichever is smaller.

    Parameters
    ----------
    model : ChainModel
        The chain.
    max_launch_speed : float
        Largest launch speed of the run, m/s.
    """
    max_launch_speed = require_positive("max_launch_speed", max_launch_speed)
    relative = 2 * max_launch_speed
    moving = _moving_masses(model)
    hertz = np.flatnonzero(model.link_kind == HERTZ)
    # Linear in N: the Hertz time is computed once per distinct (m_a, m_b, kappa).
    triples = np.stack([moving[hertz], moving[hertz + 1], model.link_stiffness[hertz]], axis=1)
    # A uniform chain has one triple: np.unique's sort is most of a short run's set-up.
    triples = triples[:1] if (triples == triples[:1]).all() else np.unique(triples, axis=0)
    steps = [math.inf]
    for m_a, m_b, kappa in triples:
        contact = hertz_contact_time(float(m_a), float(m_b), np.float64(kappa), relative)
        steps.append(contact / STEPS_PER_CONTACT_TIME)
    masses = model.masses
    for j in np.flatnonzero(model.link_kind == SPRING):
        m_a, m_b = masses[j], masses[j + 1]
        reduced = m_a * m_b / (m_a + m_b)
        period = 2 * math.pi * math.sqrt(reduced / model.link_stiffness[j])
        steps.append(period / STEPS_PER_SPRING_PERIOD)
    for side, particle in ((0, 0), (1, model.n_particles - 1)):
        if model.wall_stiffness[side] > 0:
            contact = hertz_contact_time(
                float(moving[particle]), math.inf, model.wall_stiffness[side], relative
            )
            steps.append(contact / STEPS_PER_CONTACT_TIME)
    return min(steps)


def _moving_masses(model: ChainModel) -> np.ndarray:
    """Per particle, the mass that moves with it, kg: the whole bead for either half of a
    sensor bead (the halves move together), the particle's own mass otherwise."""
    moving = np.array(model.masses, dtype=float)
    for bead in np.flatnonzero(model.bead_last > model.bead_first):
        first, last = model.bead_first[bead], model.bead_last[bead]
        moving[first : last + 1] = float(model.masses[first : last + 1].sum())
    return moving


__all__ = ["STEPS_PER_CONTACT_TIME", "STEPS_PER_SPRING_PERIOD", "default_time_step"]
