"""Ablation of the virtual experiment (:mod:`chain.apparatus.virtual`, a MODEL of the
apparatus): rerun it with one ingredient changed at a time (a variant,
:mod:`chain.pipeline.config.ablation`) at the run's seed (a variant with no overrides is
the run's experiment) and at the seeds of its replicates, and fit Delta = C F_m^(-1/6)
and a free power law as every series is fitted (:mod:`chain.analysis.recipe`);
:mod:`chain.studies.ablation_table` tabulates them.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping, Sequence

import pandas as pd

from chain.analysis.pulse_rows import pulse_table
from chain.analysis.recipe import fit_pulses
from chain.analysis.selection import select_shots
from chain.analysis.ssw import ssw_fit_table, ssw_table

log = logging.getLogger(__name__)


def variant_fits(
    traces: Sequence[pd.DataFrame],
    tolerance: float | None,
    estimator: str = "fit_full",
    ssw: bool = True,
) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """A variant's delay fits (:func:`chain.analysis.recipe.fit_pulses` rows) and, with
    ``ssw``, fits of SSW = slope x F_m at S2 behind the LSTW
    (:func:`chain.analysis.ssw.ssw_fit_table` rows; else None) with one pulse estimator,
    the shots selected by the acceptance protocol with it.

    Parameters
    ----------
    traces : sequence of DataFrame
        The trace table of each chain.
    tolerance : float or None
        Acceptance tolerance of the 5 % protocol (relative); None keeps every shot.
    estimator : str
        Pulse estimator (:data:`chain.analysis.pulses.ESTIMATORS`).
    ssw : bool
        Whether to fit the SSW too.
    """
    pulses = pd.concat([pulse_table(t, estimators=(estimator,)) for t in traces], ignore_index=True)
    selection = None
    if tolerance is not None:
        selection = select_shots(pulses, tolerance, estimator=estimator)
    if not ssw:
        return fit_pulses(pulses, selection), None
    at_s2 = pulses[(pulses["sensor"] != "S1") | (pulses["role"] != "crossed")]  # S1 rows: empty
    rows = pd.concat(
        [ssw_table(t, at_s2[at_s2["N"] == t["N"].iloc[0]], selection, estimator=estimator)
         for t in traces],
        ignore_index=True,
    )  # fmt: skip
    return fit_pulses(pulses, selection), ssw_fit_table(rows[rows["sensor"] == "S2"])


def shot_set(chains: Sequence[Mapping]) -> str:
    """The name of the shots of one replicate: its chains' settings, as JSON."""
    return json.dumps(chains, sort_keys=True)


def run_variants(
    variants: Mapping[str, Mapping],
    shots: Mapping[str, Sequence[pd.DataFrame]],
    estimator: str = "fit_full",
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Every variant's fits, replicate after replicate (:func:`variant_fits`, with one
    estimator); a replicate whose settings an earlier one had is not analysed again.
    Returns (delay fits, SSW fits of the variants with ``ssw``), each row with
    ``variant``, ``estimator`` and ``replicate`` (0 is the run's seed), the delay fits
    with the ``seeds`` of the chains.

    Parameters
    ----------
    variants : mapping
        Variant name -> {"settings": per replicate, the VirtualExperiment fields of every
        chain; "tolerance": relative, or None to keep every collision shot; "ssw": fit
        the SSW too}.
    shots : mapping
        :func:`chain.studies.ablation_shots.variant_shots` of those settings.
    estimator : str
        Pulse estimator (:data:`chain.analysis.pulses.ESTIMATORS`).
    """
    analysed, fits, ssw_fits = {}, [], []
    for name, variant in variants.items():
        tolerance, fit_ssw = variant["tolerance"], variant["ssw"]
        for replicate, chains in enumerate(variant["settings"]):
            key = json.dumps([shot_set(chains), tolerance, fit_ssw])
            if key not in analysed:
                analysed[key] = variant_fits(shots[shot_set(chains)], tolerance, estimator, fit_ssw)
            delays, ssw = analysed[key]
            seeds = " ".join(str(c["seed"]) for c in chains)
            rows = delays[["N", "C_us_N16", "C_stderr_us_N16", "exponent", "exponent_stderr"]]
            log.info("%s replicate %d (seeds %s), %s:\n%s", name, replicate, seeds, estimator, rows)
            tags = {"estimator": estimator, "replicate": replicate}
            for rows, table in ((delays.assign(**tags, seeds=seeds), fits), (ssw, ssw_fits)):
                if rows is not None:
                    table.append(rows.assign(**tags))
                    table[-1].insert(0, "variant", name)
    ssw = pd.concat(ssw_fits, ignore_index=True) if ssw_fits else pd.DataFrame(columns=["variant"])
    return pd.concat(fits, ignore_index=True), ssw
