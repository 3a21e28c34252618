"""One simulation job as plain values, and the chain and arguments they give.

:meth:`chain.pipeline.plan.run_plan.RunPlan.simulate_job` writes down, for one model and chain
of a run, every input that determines what the job computes (the *job inputs*):

====================  ===========================================================
``model``             name written in the ``model`` column
``N``                 beads
``sensors``           beads recorded, S1 first (none for a long chain)
``material``          bead material, a name of :data:`chain.physics.materials.MATERIALS`
``radius_m``          bead radius, m
``eta_s``             Kuwabara-Kono relaxation time, s
``readout``           ``felt`` (plain beads) or ``sensor`` (split sensor beads modelled)
``speeds_m_s``        launch speeds V0, m/s
``duration_s``        simulated time, s
``time_step_s``       RK4 step, s (None: the integrator's default)
``record_interval_s`` recorded sample interval, s
``max_energy_drift``  the job stops above this relative energy drift
====================  ===========================================================

The job's output depends on these values and on the code it runs (the code in its
recipe's key, :mod:`chain.pipeline.run.recipe`), on nothing else: no seed (the
simulation has no randomness) and no analysis or figure key. The dict is
JSON-serialisable; the workflow passes it to the job as a rule parameter, and the job
builds its chain from it with :func:`chain_of` (the one place a config's chain is built)
and its integration's arguments with :func:`simulation_kwargs`. This module is kept
small on purpose: a script that imports it depends on nothing of the plan's studies.
"""

from __future__ import annotations

from collections.abc import Mapping

from chain.physics.builders import uniform_chain
from chain.physics.materials import get_material
from chain.physics.model import ChainModel

#: The keys of a job's inputs, in order.
JOB_KEYS = (
    "model",
    "N",
    "sensors",
    "material",
    "radius_m",
    "eta_s",
    "readout",
    "speeds_m_s",
    "duration_s",
    "time_step_s",
    "record_interval_s",
    "max_energy_drift",
)


def chain_of(job: Mapping) -> ChainModel:
    """The chain a job integrates: N equal beads of the job's material, radius and
    Kuwabara-Kono time; its sensor beads split (sensor spring) with readout ``sensor``,
    plain beads with readout ``felt``.

    Parameters
    ----------
    job : mapping
        Job inputs (:data:`JOB_KEYS`; m, s).
    """
    return uniform_chain(
        int(job["N"]),
        get_material(job["material"]),
        job["radius_m"],
        job["eta_s"],
        sensor_beads=job["sensors"] if job["readout"] == "sensor" else (),
    )


def simulation_kwargs(job: Mapping) -> dict:
    """The integration's keyword arguments of a job (``duration``, ``dt``,
    ``record_interval``, s, and ``max_energy_drift``), as
    :func:`chain.apparatus.shots.simulate_launches` takes them.

    Parameters
    ----------
    job : mapping
        Job inputs (:data:`JOB_KEYS`).
    """
    return {
        "duration": job["duration_s"],
        "dt": job["time_step_s"],
        "record_interval": job["record_interval_s"],
        "max_energy_drift": job["max_energy_drift"],
    }
