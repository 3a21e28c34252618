"""The virtual experiment's settings from a config: ``experiment.virtual`` as it is (its
keys are the fields of VirtualExperiment), plus the run's material, radius, striker and
seed, and the chain. Shared by the checks and the ablation variants."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import fields

from chain.apparatus.virtual_settings import VirtualExperiment

#: Fields of VirtualExperiment that the run sets; every other one is a key of
#: ``experiment.virtual``, in order (:data:`VIRTUAL_KEYS`).
RUN_FIELDS = ("n_beads", "sensor_beads", "material", "radius", "striker_radius", "seed")
VIRTUAL_KEYS = tuple(f.name for f in fields(VirtualExperiment) if f.name not in RUN_FIELDS)


def virtual_experiment_settings(config: Mapping, n_beads: int, sensors: Sequence[int]) -> dict:
    """The VirtualExperiment fields, as plain values, of the chain of ``n_beads`` beads
    and ``sensors`` [S1, S2] of the schema-valid ``config``: its material and radius (m),
    ``setup.striker_radius_m``, the seed + N (the chains' shots differ), and
    ``experiment.virtual`` under its own names."""
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
    :func:`virtual_experiment_settings`); ParameterError naming a field it refuses."""
    return VirtualExperiment(**virtual_experiment_settings(config, n_beads, sensors))
