"""Ablation of the virtual experiment: rerun it with one ingredient changed at a time.

The virtual experiment (:mod:`chain.apparatus.virtual`, a MODEL of the apparatus) is
the paper's simulation plus apparatus ingredients, the 5 % acceptance protocol and its
own range of amplitudes. A variant changes some of them
(:mod:`chain.pipeline.config.ablation` maps the config's ``ablation.variants`` to the
settings of each chain). :func:`run_variant_shots` runs the virtual experiment of every
chain with those settings (the same seed as the run, so a variant with no overrides
reproduces the run's experiment) and :func:`variant_fits` fits Delta = C F_m^(-1/6) and
a free power law as every series is fitted (:mod:`chain.analysis.recipe`); replicates
repeat it with other seeds to show the spread a seed gives
(:mod:`chain.studies.ablation_table`).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from chain.analysis.pulse_rows import pulse_table
from chain.analysis.recipe import fit_pulses
from chain.analysis.rows import of_estimator
from chain.analysis.selection import select_shots
from chain.apparatus.measured import load_dataset
from chain.apparatus.virtual import VirtualExperiment, run_virtual_experiment
from chain.labels import VIRTUAL_SERIES
from chain.studies.mechanism_fits import variant_ssw_fits


def run_variant_shots(
    settings_per_chain: Sequence[Mapping],
    tolerance: float | None,
    estimators: Sequence[str] = ("fit_full",),
    series: str = VIRTUAL_SERIES,
    datasets: Sequence[str | os.PathLike] | None = None,
) -> tuple[list[pd.DataFrame], pd.DataFrame, pd.DataFrame | None]:
    """Run the virtual experiment on each chain and fit its pulses and select its shots
    as the pipeline does; returns what :func:`analyse_datasets` does.

    The shots go through the measured-data path: written in the measured-trace format
    to a temporary folder, then analysed by :func:`analyse_datasets`. With
    ``datasets`` (one folder per chain, written by the virtual experiment with exactly
    ``settings_per_chain`` and ``series``: the run's own), those are analysed instead
    of simulating the same shots again.

    Parameters
    ----------
    settings_per_chain : sequence of mapping
        VirtualExperiment fields, one mapping per chain
        (:func:`chain.pipeline.config.ablation.variant_settings`).
    tolerance : float or None
        Acceptance tolerance (relative amplitude mismatch); None keeps every shot.
    estimators : sequence of str
        Pulse estimators (:data:`chain.analysis.pulses.ESTIMATORS`).
    series : str
        Series name (the ``model`` column).
    datasets : sequence of path, optional
        The chains' dataset folders, already written.
    """
    if datasets:
        return analyse_datasets(datasets, tolerance, estimators, series)
    with tempfile.TemporaryDirectory(prefix="ablation.") as folder:
        written = []
        for i, fields in enumerate(settings_per_chain):
            written.append(Path(folder) / f"chain{i}")
            run_virtual_experiment(VirtualExperiment.from_dict(fields), written[-1], series)
        return analyse_datasets(written, tolerance, estimators, series)


def analyse_datasets(
    datasets: Sequence[str | os.PathLike],
    tolerance: float | None,
    estimators: Sequence[str] = ("fit_full",),
    series: str = VIRTUAL_SERIES,
) -> tuple[list[pd.DataFrame], pd.DataFrame, pd.DataFrame | None]:
    """Load a variant's shots, fit their pulses per chain and select the collisions
    with ``tolerance``, as the pipeline does: (the trace table of each chain, their
    pulse rows, the shot selection or None with ``tolerance`` None).

    Parameters
    ----------
    datasets : sequence of path
        Dataset folders in the measured-trace format, one per chain.
    tolerance, estimators, series
        As :func:`run_variant_shots`.
    """
    traces = [load_dataset(folder, name=series) for folder in datasets]
    table = pd.concat(
        [pulse_table(t, estimators=tuple(estimators)) for t in traces], ignore_index=True
    )
    selection = None
    if tolerance is not None:
        selection = select_shots(table, tolerance, estimator=estimators[0])
    return traces, table, selection


def variant_fits(
    traces: Sequence[pd.DataFrame],
    pulses: pd.DataFrame,
    tolerance: float | None,
    estimators: Sequence[str],
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """A variant's delay fits (:func:`chain.analysis.recipe.fit_pulses` rows) and SSW
    fits at S2 (:func:`chain.studies.mechanism_fits.variant_ssw_fits` rows with an
    ``estimator`` column) with each estimator, one after the other, each with the shot
    selection the acceptance protocol makes with that estimator.

    Every estimator is fitted so that a what-if choosing another main estimator
    reuses the variant (its simulation is the costly part); the tables reporting it
    take the main estimator's rows (:func:`chain.analysis.rows.of_estimator`).

    Parameters
    ----------
    traces : sequence of DataFrame
        The trace table of each chain (:func:`run_variant_shots`).
    pulses : DataFrame
        Their pulse rows with every estimator of ``estimators``.
    tolerance : float or None
        Acceptance tolerance of the 5 % protocol (relative); None keeps every shot.
    estimators : sequence of str
        Pulse estimators.
    """
    fits, ssw_fits = [], []
    for estimator in estimators:
        rows = of_estimator(pulses, estimator)
        selection = None
        if tolerance is not None:
            selection = select_shots(rows, tolerance, estimator=estimator)
        fits.append(fit_pulses(rows, selection))
        ssw = variant_ssw_fits(traces, rows, selection, estimator)
        ssw_fits.append(ssw.assign(estimator=estimator))
    return pd.concat(fits, ignore_index=True), pd.concat(ssw_fits, ignore_index=True)
