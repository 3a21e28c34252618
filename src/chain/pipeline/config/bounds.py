"""Bounds of config values that depend on other keys.

The JSON schema (``workflow/schemas/config.schema.yaml``) holds every bound of a key on
its own (``minimum``, ``maxItems``, ...). The bounds here need a second key: a sensor
bead against the collision point, a record interval against the time step and the
narrowest pulse, a duration against the slowest wave, a detection threshold against the
smallest pulse, a tolerance against the shots' mismatch, names that must stay apart
after rounding. :func:`check_bounds` runs them (from
:func:`chain.pipeline.config.check.check_config`, before any job), on the run and on every
ablation variant, and raises :class:`ConfigError` naming the key, as every config check
does:

* :mod:`chain.pipeline.config.bounds_run`: the simulated run (sensors, simulation, long
  chains, LAMMPS);
* :mod:`chain.pipeline.config.bounds_experiment`: the virtual experiment;
* :mod:`chain.pipeline.config.bounds_table`: the table ``docs/config_bounds.md`` of
  every key's smallest and largest value, generated from the schema and its ``RULES``.

This module reads no file and knows no Snakemake.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping

from chain.errors import ConfigError, key_label
from chain.pipeline.config.bounds_experiment import check_experiment_bounds
from chain.pipeline.config.bounds_run import check_run_bounds


def variant_config(config: Mapping, overrides: Mapping) -> dict:
    """The config an ablation variant runs: ``experiment.virtual`` with the variant's
    overrides (``striker_radius_m`` into ``setup``, ``tolerance`` into ``experiment``),
    the virtual experiment as the source, and no variants of its own.

    Parameters
    ----------
    config : mapping
        A schema-valid config (defaults filled in).
    overrides : mapping
        The variant's ``set``.
    """
    derived = copy.deepcopy(dict(config))
    experiment = derived["experiment"]
    experiment.update(source="virtual", datasets=[])
    for key, value in overrides.items():
        if key == "striker_radius_m":
            derived["setup"]["striker_radius_m"] = value
        elif key == "tolerance":
            experiment["tolerance"] = value
        else:
            experiment["virtual"][key] = value
    derived["ablation"] = {"variants": []}
    return derived


def _check_variants(config: Mapping, check: Callable[[Mapping], None]) -> None:
    # Every variant, whatever the source: `snakemake ablation` runs them all (the
    # default run those with default_run), each with the virtual experiment.
    for i, variant in enumerate(config.get("ablation", {}).get("variants", [])):
        overrides = variant.get("set") or {}
        try:
            check(variant_config(config, overrides))
        except ConfigError as error:
            raise ConfigError(
                f"config key {key_label(['ablation', 'variants', i, 'set'])!r} (variant "
                f"{variant['name']!r}): with its settings, {error}"
            ) from None


def check_bounds(config: Mapping, check: Callable[[Mapping], None] | None = None) -> None:
    """Check the bounds of a schema-valid config that depend on other keys.

    Parameters
    ----------
    config : mapping
        The config after schema validation (defaults filled in) and the checks of
        :func:`chain.pipeline.config.check.check_config` up to the ablation.
    check : callable, optional
        The whole config check (:func:`chain.pipeline.config.check.check_config`), run again
        on each ablation variant's config (:func:`variant_config`); None skips the
        variants.

    Raises
    ------
    ConfigError
        Naming the first offending key.
    """
    check_run_bounds(config)
    if config["experiment"]["source"] == "virtual":
        check_experiment_bounds(config)
    if check is not None:
        _check_variants(config, check)
