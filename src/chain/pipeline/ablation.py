"""Ablation of the virtual experiment: rerun it with one ingredient changed at a time.

The virtual experiment (:mod:`chain.apparatus.virtual`, a MODEL of the apparatus) is
the paper's simulation plus apparatus ingredients: strikers instead of a launched end
bead, split sensor beads instead of a point readout, Kuwabara-Kono dissipation, noise
and a digitiser, shot-to-shot speed mismatch and launch jitter, the 5 % acceptance
protocol and its own range of amplitudes. A config's ``ablation.variants`` lists named
variants, each a set of overrides of ``experiment.virtual`` keys (plus
``striker_radius_m`` of ``setup`` and ``tolerance`` of ``experiment``; ``tolerance: null``
switches the acceptance protocol off). :func:`run_variant` runs the virtual experiment
of every configured chain with those overrides (the same seed as the run, so a variant
with no overrides reproduces the run's experiment) and fits Delta = C F_m^(-1/6) and a
free power law (:func:`chain.analysis.delays.delay_fit_table`); ``replicates`` > 1
repeats it with other seeds (seed + 1000 k) to show the spread a seed gives.

This module maps config keys; it reads no config file and knows no Snakemake.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from chain.analysis.delays import delay_fit_table, delay_table
from chain.analysis.rows import flag_unusable
from chain.analysis.selection import select_shots
from chain.errors import ConfigError, ParameterError
from chain.errors import key_label as key_name
from chain.labels import VIRTUAL_LABEL, VIRTUAL_SERIES
from chain.pipeline.virtual_config import VIRTUAL_KEYS, virtual_experiment_settings

#: Keys a variant may set besides those of ``experiment.virtual``.
EXTRA_KEYS = ("striker_radius_m", "tolerance")

#: Seed offset between replicates of a variant.
REPLICATE_SEED_STEP = 1000

#: Columns of :func:`ablation_table`, in order (after ``exponent_stderr``: extras).
ABLATION_COLUMNS = (
    "variant",
    "N",
    "C",
    "C_stderr",
    "exponent",
    "exponent_stderr",
    "n_points",
    "estimator",
    "n_seeds",
    "C_seed_mean",
    "C_seed_std",
    "exponent_seed_mean",
    "exponent_seed_std",
    "series",
    "overrides",
)


def ablation_variants(config: Mapping) -> list[dict]:
    """The variants of a schema-valid config: name, description, replicates,
    default_run, set, mechanism ("" unless the variant is a candidate of the mechanism
    study, tables/ssw_mechanisms.csv)."""
    variants = config.get("ablation", {}).get("variants", [])
    return [
        {
            "name": v["name"],
            "description": v.get("description", ""),
            "replicates": int(v.get("replicates", 1)),
            "default_run": bool(v.get("default_run", False)),
            "set": dict(v.get("set") or {}),
            "mechanism": v.get("mechanism") or "",
        }
        for v in variants
    ]


def variant_settings(
    config: Mapping, variant: Mapping, n_beads: int, sensors: Sequence[int], replicate: int = 0
) -> dict:
    """VirtualExperiment fields of one chain of one variant (plain values).

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    variant : mapping
        An entry of :func:`ablation_variants`.
    n_beads : int
        N.
    sensors : sequence of int
        Sensor beads [S1, S2].
    replicate : int
        Replicate number k >= 0; the seed is the run's (seed + N) + 1000 k.
    """
    settings = virtual_experiment_settings(config, n_beads, sensors)
    for key, value in variant["set"].items():
        if key in VIRTUAL_KEYS:
            settings[key] = value
        elif key == "striker_radius_m":
            settings["striker_radius"] = value
    settings["seed"] += REPLICATE_SEED_STEP * int(replicate)
    return settings


def variant_tolerance(config: Mapping, variant: Mapping) -> float | None:
    """Acceptance tolerance of a variant; None: every collision shot is kept."""
    overrides = variant["set"]
    if "tolerance" in overrides:
        return overrides["tolerance"]
    return config.get("experiment", {}).get("tolerance", 0.05)


def check_ablation(config: Mapping) -> None:
    """Check the ablation variants of a schema-valid config: unique names, known keys,
    settings the virtual experiment accepts for every chain.

    Raises
    ------
    ConfigError
        Naming ``ablation.variants[i]`` and the key.
    """
    # Imported here: chain.apparatus.virtual pulls in the simulation core.
    from chain.apparatus.virtual import VirtualExperiment, check_switches

    seen: dict[str, int] = {}
    for i, variant in enumerate(ablation_variants(config)):
        path = ["ablation", "variants", i]
        if variant["name"] in seen:
            raise ConfigError(
                f"config key {key_name([*path, 'name'])!r}: {variant['name']!r} is listed "
                f"twice (also ablation.variants[{seen[variant['name']]}]); allowed: each "
                "name once (file names)"
            )
        seen[variant["name"]] = i
        for key in variant["set"]:
            if key not in VIRTUAL_KEYS and key not in EXTRA_KEYS:
                allowed = ", ".join([*VIRTUAL_KEYS, *EXTRA_KEYS])
                raise ConfigError(
                    f"config key {key_name([*path, 'set', key])!r}: unknown; allowed: {allowed}"
                )
        for entry in config["chains"]:
            try:
                settings = VirtualExperiment.from_dict(
                    variant_settings(config, variant, entry["N"], entry["sensors"])
                )
                check_switches(settings)
            except ParameterError as error:
                raise ConfigError(
                    f"config key {key_name([*path, 'set'])!r}: {error} (chain N = {entry['N']})"
                ) from None


def run_variant(
    settings_per_chain: Sequence[Mapping],
    tolerance: float | None,
    estimators: Sequence[str] = ("fit_full",),
    series: str = VIRTUAL_SERIES,
) -> pd.DataFrame:
    """Run the virtual experiment on each chain, analyse it as the pipeline does, and
    fit |Delta| against F_m (:func:`run_variant_shots`, then :func:`variant_delay_fits`).

    Parameters
    ----------
    settings_per_chain : sequence of mapping
        VirtualExperiment fields, one mapping per chain (:func:`variant_settings`).
    tolerance : float or None
        Acceptance tolerance (relative amplitude mismatch); None keeps every shot.
    estimators : sequence of str
        Pulse estimators (:data:`chain.analysis.pulses.ESTIMATORS`).
    series : str
        Series name (the ``model`` column).

    Returns
    -------
    DataFrame
        :data:`chain.analysis.delays.DELAY_FIT_COLUMNS` rows of source "experiment".
    """
    _, pulses, selection = run_variant_shots(settings_per_chain, tolerance, estimators, series)
    return variant_delay_fits(pulses, selection)


def run_variant_shots(
    settings_per_chain: Sequence[Mapping],
    tolerance: float | None,
    estimators: Sequence[str] = ("fit_full",),
    series: str = VIRTUAL_SERIES,
) -> tuple[list[pd.DataFrame], pd.DataFrame, pd.DataFrame | None]:
    """Run the virtual experiment on each chain and fit its pulses and select its shots
    as the pipeline does (parameters as :func:`run_variant`).

    The shots go through the measured-data path (written in the measured-trace format
    to a temporary folder and loaded back), pulses are fitted per chain and collisions
    are selected with ``tolerance``.

    Returns
    -------
    traces : list of DataFrame
        The trace table of each chain.
    pulses : DataFrame
        Their pulse rows (:func:`chain.analysis.pulse_rows.pulse_table`).
    selection : DataFrame or None
        The shot selection (None with ``tolerance`` None).
    """
    # Imported here: chain.apparatus pulls in the simulation core, and the pulse fits
    # scipy.signal, which the ablation table job (it only reads fits) does not need.
    from chain.analysis.pulse_rows import pulse_table
    from chain.apparatus.measured import load_dataset
    from chain.apparatus.virtual import VirtualExperiment, run_virtual_experiment

    pulses, traces = [], []
    with tempfile.TemporaryDirectory(prefix="ablation.") as folder:
        for i, fields in enumerate(settings_per_chain):
            settings = VirtualExperiment.from_dict(fields)
            dataset = Path(folder) / f"chain{i}"
            run_virtual_experiment(settings, dataset, series)
            traces.append(load_dataset(dataset, name=series))
            pulses.append(pulse_table(traces[-1], estimators=tuple(estimators)))
    table = pd.concat(pulses, ignore_index=True)
    selection = None
    if tolerance is not None:
        selection = select_shots(table, tolerance, estimator=estimators[0])
    return traces, table, selection


def variant_delay_fits(pulses: pd.DataFrame, selection: pd.DataFrame | None) -> pd.DataFrame:
    """|Delta| = C F_m^(-1/6) and the free power law, pooled and per chain, of the pulses
    of :func:`run_variant_shots` (:func:`chain.analysis.delays.delay_fit_table` rows)."""
    delays = delay_table(pulses, selection=selection)
    return delay_fit_table(flag_unusable(delays, ["F_m_N", "delay_us"], "delay rows"))


def ablation_table(fits: Mapping[str, pd.DataFrame], overrides: Mapping[str, str]) -> pd.DataFrame:
    """Rows of ``ablation_exponent.csv`` from the fits of every variant.

    Parameters
    ----------
    fits : mapping
        Variant name -> its fits (:func:`run_variant` rows with a ``replicate``
        column; replicate 0 is the run's seed).
    overrides : mapping
        Variant name -> its overrides as text (for the ``overrides`` column).

    Returns
    -------
    DataFrame
        Columns :data:`ABLATION_COLUMNS`: C (us N^1/6) and the free exponent with their
        standard errors at the run's seed per N and pooled, and the mean and standard
        deviation over the seeds of the replicates.
    """
    rows = []
    for name, table in fits.items():
        for (n_beads, estimator), group in table.groupby(["N", "estimator"], sort=False):
            first = group[group["replicate"] == 0].iloc[0]
            c = group["C_us_N16"].to_numpy(dtype=float)
            p = group["exponent"].to_numpy(dtype=float)
            many = len(group) > 1
            rows.append(
                {
                    "variant": name,
                    "N": n_beads,
                    "C": first["C_us_N16"],
                    "C_stderr": first["C_stderr_us_N16"],
                    "exponent": first["exponent"],
                    "exponent_stderr": first["exponent_stderr"],
                    "n_points": first["n_points"],
                    "estimator": estimator,
                    "n_seeds": len(group),
                    "C_seed_mean": float(np.mean(c)),
                    "C_seed_std": float(np.std(c, ddof=1)) if many else float("nan"),
                    "exponent_seed_mean": float(np.mean(p)),
                    "exponent_seed_std": float(np.std(p, ddof=1)) if many else float("nan"),
                    "series": VIRTUAL_LABEL,
                    "overrides": overrides.get(name, ""),
                }
            )
    return pd.DataFrame(rows, columns=ABLATION_COLUMNS)


def overrides_text(variant: Mapping) -> str:
    """A variant's overrides as ``key=value; ...`` (``none`` for the run as configured)."""
    return "; ".join(f"{k}={v}" for k, v in variant["set"].items()) or "none"
