"""The virtual experiment's settings from a config: ``experiment.virtual`` as it is
(its keys are the fields of :class:`chain.apparatus.virtual.VirtualExperiment`), plus
the run's material, radius, striker and seed, and the chain.

Its own module so that both :mod:`chain.pipeline.config.check` (the checks) and
:mod:`chain.pipeline.config.ablation` (the variants) use it without importing each other.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import fields

from chain.apparatus.virtual_settings import VirtualExperiment

#: Fields of VirtualExperiment that the run sets (the chain, material, radius, striker,
#: seed); every other field is a key of ``experiment.virtual``.
RUN_FIELDS = ("n_beads", "sensor_beads", "material", "radius", "striker_radius", "seed")

#: The keys of ``experiment.virtual``: the other fields of VirtualExperiment, in order.
VIRTUAL_KEYS = tuple(f.name for f in fields(VirtualExperiment) if f.name not in RUN_FIELDS)


def virtual_experiment_settings(config: Mapping, n_beads: int, sensors: Sequence[int]) -> dict:
    """The :class:`~chain.apparatus.virtual.VirtualExperiment` fields of one chain of a
    config, as plain values (lists for tuples).

    Material and radius are the run's, the striker radius ``setup.striker_radius_m``,
    the seed the top-level seed + N (so that the chains' shots differ), the rest
    ``experiment.virtual`` under its own names.

    Parameters
    ----------
    config : mapping
        A schema-valid config (defaults filled in).
    n_beads : int
        N.
    sensors : sequence of int
        Sensor beads [S1, S2].
    """
    return {
        **config["experiment"]["virtual"],
        "n_beads": int(n_beads),
        "sensor_beads": [int(b) for b in sensors],
        "material": config["material"],
        "radius": config["radius_m"],
        "striker_radius": config["setup"]["striker_radius_m"],
        "seed": int(config["seed"]) + int(n_beads),
    }


def virtual_experiment(config: Mapping, n_beads: int, sensors: Sequence[int]) -> VirtualExperiment:
    """The virtual experiment of one chain of a config (parameters as
    :func:`virtual_experiment_settings`).

    Raises
    ------
    chain.errors.ParameterError
        Naming the field the virtual experiment refuses.
    """
    return VirtualExperiment(**virtual_experiment_settings(config, n_beads, sensors))
