"""The lab's measured-trace format (``data/README.md``) and its loader.

A *dataset* is one folder holding one CSV file per shot (oscilloscope export: time
in seconds, one voltage column per sensor) and a ``metadata.yaml`` that says what
the shots are::

    data/<dataset>/
        metadata.yaml
        shot_0000.csv        t_s,bead9_V,bead17_V
        ...

The format lives in four modules, one concept each (the names the pipeline and the
virtual experiment use are re-exported here):

* :mod:`chain.apparatus.measured_format`  names, tolerances, :class:`MeasuredDataError`;
* :mod:`chain.apparatus.metadata`  ``metadata.yaml``, validated against the JSON schema
  ``metadata.schema.yaml`` (the format's specification);
* :mod:`chain.apparatus.shot_files`  one shot CSV: read with every problem listed, write,
  dead or saturated channels;
* :mod:`chain.apparatus.dataset_check`  a whole dataset at once, cached by file content.

:func:`load_dataset` (this module) turns a good dataset into a trace table
(:mod:`chain.traces`, source ``experiment``) in newtons. Any defect raises
:class:`MeasuredDataError` listing every problem, one line each, naming the file and,
where it applies, the line a person sees in an editor (the CSV header is line 1).
"""

from __future__ import annotations

import os
from pathlib import Path

import pandas as pd

from chain.apparatus.acquisition import volts_to_newtons
from chain.apparatus.dataset_check import DatasetCheck, check_dataset
from chain.apparatus.measured_format import (
    FORMAT_NAME,
    MAX_PROBLEMS,
    METADATA_FILE,
    STANDARD_GRAVITY,
    MeasuredDataError,
    problem_list,
)
from chain.apparatus.metadata import DatasetMetadata, read_metadata, write_metadata
from chain.apparatus.shot_files import read_shot_csv, write_shot_csv
from chain.traces import META_COLUMNS, sensor_column, validate_traces

#: What to do with a shot that has a dead or saturated channel.
BAD_CHANNEL_POLICIES = ("stop", "skip")


def _shot_table(meta: DatasetMetadata, model: str, shot: int, time, volts) -> pd.DataFrame:
    entry = meta.shots[shot]
    columns = {
        sensor_column(bead): volts_to_newtons(volts[i], meta.sensitivity_mV_per_N[i])
        for i, bead in enumerate(meta.sensor_beads)
    }
    return pd.DataFrame(
        {
            "source": "experiment",
            "model": model,
            "N": meta.n_beads,
            "shot": shot,
            "kind": entry.kind,
            "amplitude": entry.amplitude,
            "v0_left_m_s": entry.impact_speed_m_s,
            "v0_right_m_s": 0.0 if entry.kind == "reference" else entry.impact_speed_m_s,
            "t_s": time,
            **columns,
        }
    )


def usable_shots(check: DatasetCheck, bad_channels: str = "stop") -> list[int]:
    """Shots of a checked dataset to load, or :class:`MeasuredDataError` listing why not.

    Parameters
    ----------
    check : DatasetCheck
        :func:`chain.apparatus.dataset_check.check_dataset` of the dataset.
    bad_channels : {"stop", "skip"}
        A shot with a dead or saturated channel stops the load (naming file and
        channel), or is left out (and reported by the caller).
    """
    if bad_channels not in BAD_CHANNEL_POLICIES:
        raise ValueError(
            f"bad_channels must be one of {BAD_CHANNEL_POLICIES}, got {bad_channels!r}"
        )
    check.raise_problems()
    if bad_channels == "stop" and check.faults:
        faults = [line for lines in check.faults.values() for line in lines]
        hint = "(or set experiment.bad_channels: skip to leave such shots out)"
        raise MeasuredDataError(problem_list(faults, MAX_PROBLEMS) + f"\n{hint}")
    return [shot for shot in range(len(check.metadata.shots)) if shot not in check.faults]


def load_dataset(
    folder: str | os.PathLike,
    name: str | None = None,
    *,
    bad_channels: str = "stop",
    cache_dir: str | os.PathLike | None = None,
) -> pd.DataFrame:
    """Load a measured dataset as a trace table in newtons.

    Parameters
    ----------
    folder : path
        Dataset folder with ``metadata.yaml`` and the shot CSV files.
    name : str, optional
        Value of the ``model`` column; default the metadata ``name``, else the folder
        name.
    bad_channels : {"stop", "skip"}
        What a dead or saturated channel does (:func:`usable_shots`); skipped shots
        are absent from the table (their numbers are not reused).
    cache_dir : path, optional
        Verdict cache of :func:`chain.apparatus.dataset_check.check_dataset`.

    Returns
    -------
    DataFrame
        Trace table (:mod:`chain.traces`): source ``experiment``; shot = position in
        the metadata shot list (0, 1, ...); amplitude = nominal-amplitude group;
        v0_left_m_s / v0_right_m_s = nominal impact speeds (sqrt(2 g h) from drop
        heights; the right one is 0 for a reference shot) or NaN when not given;
        ``force_bead<n>_N`` = volts / sensitivity.

    Raises
    ------
    MeasuredDataError
        Listing every problem (file, line, column), up to :data:`MAX_PROBLEMS`.
    """
    folder = Path(folder)
    check = check_dataset(folder, cache_dir=cache_dir, keep_data=True)
    meta = check.metadata
    model = name or meta.name or folder.resolve().name
    tables = []
    for shot in usable_shots(check, bad_channels):
        data = check.data.get(shot)
        if data is None:  # its verdict came from the cache: parse it now
            path = folder / meta.shots[shot].file
            time, volts = read_shot_csv(
                path, meta.sensor_beads, meta.sampling_interval_s, meta.samples
            )
        else:  # parsed by the check, by the same reader
            time, volts = data[:, 0], data[:, 1:].T.copy()
        tables.append(_shot_table(meta, model, shot, time, volts))
    if not tables:
        raise MeasuredDataError(f"{folder}: every shot was skipped (bad channels); nothing to load")
    table = pd.concat(tables, ignore_index=True)
    table = table[list(META_COLUMNS) + [sensor_column(b) for b in meta.sensor_beads]]
    return validate_traces(table, where=str(folder))


__all__ = [
    "BAD_CHANNEL_POLICIES",
    "FORMAT_NAME",
    "METADATA_FILE",
    "STANDARD_GRAVITY",
    "MeasuredDataError",
    "load_dataset",
    "read_metadata",
    "usable_shots",
    "write_metadata",
    "write_shot_csv",
]
