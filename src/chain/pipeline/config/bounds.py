"""Bounds of config values that depend on other keys.

The schema holds every bound of a key on its own; :func:`check_bounds` checks those that
need a second key, on the run and on every ablation variant, and raises
:class:`ConfigError` naming the key: :mod:`.bounds_run` (the simulated run, long chains,
LAMMPS), :mod:`.bounds_experiment` (the virtual experiment); :mod:`.bounds_table` writes
the table ``docs/config_bounds.md`` of every key's smallest and largest value.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping

from chain.errors import ConfigError, key_label
from chain.pipeline.config.bounds_experiment import check_experiment_bounds
from chain.pipeline.config.bounds_run import check_run_bounds


def variant_config(config: Mapping, overrides: Mapping) -> dict:
    """The config an ablation variant runs: the schema-valid ``config`` with the
    variant's ``overrides`` (its ``set``: ``striker_radius_m`` into ``setup``,
    ``tolerance`` into ``experiment``, the rest into ``experiment.virtual``), the virtual
    experiment as the source, and no variants of its own."""
    derived = copy.deepcopy(dict(config))
    experiment = derived["experiment"]
    experiment.update(source="virtual", datasets=[])
    homes = {"striker_radius_m": derived["setup"], "tolerance": experiment}
    for key, value in overrides.items():
        homes.get(key, experiment["virtual"])[key] = value
    derived["ablation"] = {"variants": []}
    return derived


def check_bounds(config: Mapping, check: Callable[[Mapping], None] | None = None) -> None:
    """Check the bounds that depend on other keys of ``config`` (schema-valid, checked up
    to the ablation), then run ``check`` (the whole config check; None: not) on each
    ablation variant's config (:func:`variant_config`), whatever the source
    (``studies.ablation: full`` runs them all). :class:`ConfigError` naming the first
    offending key."""
    check_run_bounds(config)
    if config["experiment"]["source"] == "virtual":
        check_experiment_bounds(config)
    if check is None:
        return
    for i, variant in enumerate(config.get("ablation", {}).get("variants", [])):
        try:
            check(variant_config(config, variant.get("set") or {}))
        except ConfigError as error:
            raise ConfigError(
                f"config key {key_label(['ablation', 'variants', i, 'set'])!r} (variant "
                f"{variant['name']!r}): with its settings, {error}"
            ) from None
