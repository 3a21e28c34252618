"""The shots of the ablation's variants (the virtual experiment, a MODEL, not data),
made in memory: each distinct launch integrated once for all of them, the shots that are
the run's own read from its datasets (:func:`variant_shots`); their analysis is
:mod:`chain.studies.ablation`'s, in another job, so that an analysis what-if integrates
nothing."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence

import pandas as pd

from chain.apparatus.virtual import VirtualExperiment
from chain.apparatus.virtual_dataset import virtual_traces
from chain.labels import VIRTUAL_SERIES
from chain.studies.ablation import shot_set


def variant_shots(
    variants: Mapping[str, Sequence],
    run: Sequence[Mapping],
    datasets: Sequence[str | os.PathLike],
    series: str = VIRTUAL_SERIES,
) -> dict[str, list[pd.DataFrame]]:
    """The shots of every replicate of every variant, made in memory
    (:func:`chain.apparatus.virtual_dataset.virtual_traces`): each distinct launch
    integrated once for all of them, the shots that are the run's read from its
    datasets. Returns shot set -> the trace table of each chain, a shot set named by
    its chains' settings (:func:`chain.studies.ablation.shot_set`); replicates with
    equal settings share one.

    Parameters
    ----------
    variants : mapping
        Variant name -> per replicate, the VirtualExperiment fields of every chain
        (:func:`chain.pipeline.config.ablation.variant_settings`).
    run, datasets : sequence
        The run's virtual experiment of each chain (its fields) and its dataset folder.
    series : str
        Series name (the ``model`` column).
    """
    runs = [(VirtualExperiment.from_dict(r), d) for r, d in zip(run, datasets, strict=True)]
    known, shots = {}, {}
    for replicates in variants.values():
        for chains in replicates:
            if shot_set(chains) not in shots:
                settings = [VirtualExperiment.from_dict(c) for c in chains]
                shots[shot_set(chains)] = [virtual_traces(s, series, known, r)
                                           for s, r in zip(settings, runs)]  # fmt: skip
    return shots
