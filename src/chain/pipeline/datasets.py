"""The measured datasets a config uses, checked before any job runs.

:func:`check_experiment_datasets` runs :func:`chain.apparatus.dataset_check.check_dataset`
on every dataset folder of ``experiment.datasets`` when the pipeline builds its DAG, and
stops with one :class:`~chain.pipeline.config.ConfigError` that lists every problem of
every dataset (up to a limit each), one console line per problem: file, line, column,
what was expected. Shots with a dead or saturated channel stop the run too, unless
``experiment.bad_channels: skip``; then :func:`skipped_shot_rows` gives the rows that
``experiment/selection.csv`` lists them with (kept False, the channel as the reason),
so the summary counts them among the rejected shots.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from chain.analysis.selection import SELECTION_COLUMNS, SKIPPED_REASON
from chain.apparatus.dataset_check import DatasetCheck, check_dataset
from chain.apparatus.measured import MeasuredDataError, usable_shots
from chain.pipeline.config import ConfigError, ExperimentPart

#: Where the pipeline keeps the verdicts of the dataset check (by file content).
DEFAULT_CACHE = Path(".snakemake") / "hertzchain" / "dataset-check"


def bad_channel_policy(config: Mapping) -> str:
    """``experiment.bad_channels`` of a config (``stop`` or ``skip``)."""
    return config.get("experiment", {}).get("bad_channels", "stop")


def check_experiment_datasets(
    config: Mapping,
    parts: Sequence[ExperimentPart],
    root: str | os.PathLike = ".",
    cache_dir: str | os.PathLike | None = DEFAULT_CACHE,
) -> None:
    """Check every measured dataset of a config's experiment; raise listing all problems.

    Parameters
    ----------
    config : mapping
        A config that passed :func:`chain.pipeline.config.check_config`.
    parts : sequence of ExperimentPart
        :func:`chain.pipeline.config.experiment_parts` of it (virtual parts, whose
        datasets are pipeline outputs, are skipped).
    root : path
        Folder that relative dataset paths start from.
    cache_dir : path or None
        Verdict cache (relative paths start from ``root``); None checks every file.

    Raises
    ------
    ConfigError
        ``experiment.datasets: N problems in M datasets`` then one line per problem.
    """
    policy = bad_channel_policy(config)
    cache = None if cache_dir is None else Path(root) / cache_dir
    messages, bad = [], 0
    for part in parts:
        if part.folder is None:
            continue
        folder = Path(part.folder)
        try:
            usable_shots(check_dataset(Path(root) / folder, cache_dir=cache), policy)
        except MeasuredDataError as error:
            messages.append(str(error))
            bad += 1
    if messages:
        raise ConfigError(
            f"config key 'experiment.datasets': {bad} of {len(parts)} datasets cannot be "
            "used (data/README.md; every problem below, up to 20 per dataset):\n"
            + "\n".join(messages)
        )


def skipped_shot_rows(check: DatasetCheck, name: str) -> pd.DataFrame:
    """Selection rows (:data:`chain.analysis.selection.SELECTION_COLUMNS`) of the shots
    of a dataset left out for a dead or saturated channel, the channel as the reason.

    Parameters
    ----------
    check : DatasetCheck
        :func:`chain.apparatus.dataset_check.check_dataset` of the dataset.
    name : str
        Series name of the dataset (the ``model`` column).
    """
    rows = [
        {
            "source": "experiment",
            "model": name,
            "N": check.metadata.n_beads,
            "shot": shot,
            "kind": check.metadata.shots[shot].kind,
            "amplitude": check.metadata.shots[shot].amplitude,
            "kept": False,
            "reason": f"{SKIPPED_REASON}: " + "; ".join(faults),
        }
        for shot, faults in sorted(check.faults.items())
    ]
    return pd.DataFrame(rows, columns=list(SELECTION_COLUMNS))
