"""The ``ablation`` section of a config: the variants, their virtual-experiment settings
and acceptance tolerance per chain, and their checks.

Each variant overrides keys of ``experiment.virtual`` (and ``setup.striker_radius_m``,
``experiment.tolerance``; null keeps every shot); :mod:`chain.studies.ablation` runs them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from chain.apparatus.virtual_settings import VirtualExperiment, check_switches
from chain.errors import ParameterError
from chain.pipeline.config import fail
from chain.pipeline.config.virtual import VIRTUAL_KEYS, virtual_experiment_settings

#: Keys a variant may set besides those of ``experiment.virtual``.
EXTRA_KEYS = ("striker_radius_m", "tolerance")

#: Seed offset between replicates of a variant.
REPLICATE_SEED_STEP = 1000


def ablation_variants(config: Mapping) -> list[dict]:
    """The variants of a schema-valid config: name, description, replicates,
    default_run, set, mechanism ("" unless the variant is a candidate of the mechanism
    study, tables/ssw_mechanisms.csv)."""
    return [
        {
            "name": v["name"],
            "description": v["description"],
            "replicates": int(v["replicates"]),
            "default_run": bool(v["default_run"]),
            "set": dict(v["set"]),
            "mechanism": v["mechanism"],
        }
        for v in config["ablation"]["variants"]
    ]


def variant_settings(
    config: Mapping, variant: Mapping, n_beads: int, sensors: Sequence[int], replicate: int = 0
) -> dict:
    """VirtualExperiment fields (plain values) of ``variant`` (:func:`ablation_variants`)
    on the chain of ``n_beads`` beads and ``sensors`` [S1, S2] of the schema-valid
    ``config``, replicate number ``replicate`` k >= 0 (the seed: seed + N + 1000 k)."""
    settings = virtual_experiment_settings(config, n_beads, sensors)
    for key, value in variant["set"].items():
        if key in VIRTUAL_KEYS:
            settings[key] = value
        elif key == "striker_radius_m":
            settings["striker_radius"] = value
    settings["seed"] += REPLICATE_SEED_STEP * int(replicate)
    return settings


def variant_tolerance(config: Mapping, variant: Mapping) -> float | None:
    """Acceptance tolerance of a variant (relative amplitude mismatch); None: every
    collision shot is kept."""
    return variant["set"].get("tolerance", config["experiment"]["tolerance"])


def check_ablation(config: Mapping) -> None:
    """Check the ablation variants of a schema-valid config: unique names, known keys,
    settings the virtual experiment accepts for every chain; else
    :class:`~chain.errors.ConfigError` naming ``ablation.variants[i]`` and the key."""
    seen: dict[str, int] = {}
    for i, variant in enumerate(ablation_variants(config)):
        path = ["ablation", "variants", i]
        if variant["name"] in seen:
            fail(
                [*path, "name"],
                f"{variant['name']!r} is listed twice (also ablation.variants"
                f"[{seen[variant['name']]}]); allowed: each name once (file names)",
            )
        seen[variant["name"]] = i
        for key in variant["set"]:
            if key not in VIRTUAL_KEYS and key not in EXTRA_KEYS:
                allowed = ", ".join(VIRTUAL_KEYS + EXTRA_KEYS)
                fail([*path, "set", key], f"unknown; allowed: {allowed}")
        for entry in config["chains"]:
            try:
                settings = variant_settings(config, variant, entry["N"], entry["sensors"])
                check_switches(VirtualExperiment.from_dict(settings))
            except ParameterError as error:
                fail([*path, "set"], f"{error} (chain N = {entry['N']})")
