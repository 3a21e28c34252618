"""Check a whole measured dataset at once, fast enough to run before every pipeline run.

:func:`check_dataset` reads ``metadata.yaml`` (:mod:`chain.apparatus.metadata`) and every
shot file (:mod:`chain.apparatus.shot_files`) and returns every problem found, one line
each, plus the dead or saturated channels of each shot. The verdict on one shot file
depends only on its bytes, on the rules it is held to (sensor beads, sampling
interval, sample count, ADC limits) and on this code, so it is cached under a hash of
the first two in a folder for this code (the pipeline names its folder by a digest of
the code, :data:`chain.pipeline.plan.datasets.DEFAULT_CACHE`): a thousand unchanged
shots are re-checked by hashing them, in a fraction of a second.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from chain.apparatus.measured_format import (
    MAX_PROBLEMS,
    METADATA_FILE,
    MeasuredDataError,
    problem_list,
)
from chain.apparatus.metadata import DatasetMetadata, read_metadata
from chain.apparatus.shot_files import channel_faults, saturation_limits, shot_file_problems
from chain.atomic import write_text_atomic

#: Stands for the file's path in cached messages (a copied file is the same verdict).
_FILE = "\x00file\x00"


@dataclass(frozen=True)
class DatasetCheck:
    """What :func:`check_dataset` found in one dataset.

    Attributes
    ----------
    folder : str
        The dataset folder.
    metadata : DatasetMetadata
        Its checked ``metadata.yaml``.
    problems : tuple of str
        Format problems (the dataset cannot be loaded), one line each: file, line,
        column, what was expected.
    faults : dict of int to tuple of str
        Shot index -> its dead or saturated channels, one line each (the data parse,
        but the shot cannot be trusted).
    data : dict of int to array
        With ``keep_data``: shot index -> its samples as parsed by the check, (S, 1 +
        n_sensors), time (s) then volts (V), for the shots read (not those whose verdict
        came from the cache), so that a load need not parse them again.
    """

    folder: str
    metadata: DatasetMetadata
    problems: tuple[str, ...] = ()
    faults: dict[int, tuple[str, ...]] = field(default_factory=dict)
    data: dict[int, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    def raise_problems(self, limit: int = MAX_PROBLEMS) -> None:
        """Raise :class:`MeasuredDataError` listing the problems (up to ``limit``), if any."""
        if self.problems:
            raise MeasuredDataError(problem_list(self.problems, limit))


def _rules(meta: DatasetMetadata) -> str:
    """What a shot file is held to, as text (part of the cache key)."""
    return json.dumps(
        {
            "sensor_beads": list(meta.sensor_beads),
            "sampling_interval_s": meta.sampling_interval_s,
            "samples": meta.samples,
            "limits_V": saturation_limits(meta.adc_range_V, meta.adc_bits),
        },
        sort_keys=True,
    )


def _check_file(path: Path, meta: DatasetMetadata, limit: int) -> tuple[dict, np.ndarray | None]:
    """The verdict on one shot file, and its samples (None when it has problems)."""
    data, problems = shot_file_problems(
        path, meta.sensor_beads, meta.sampling_interval_s, meta.samples, limit
    )
    faults = []
    if data is not None:
        limits = saturation_limits(meta.adc_range_V, meta.adc_bits)
        faults = channel_faults(str(path), data[:, 1:].T, meta.sensor_beads, limits)
    return {"problems": problems, "faults": faults}, data


def _cached_check(path: Path, meta: DatasetMetadata, rules: str, cache: Path | None, limit):
    """:func:`_check_file`, the verdict remembered under the hash of the rules and the
    file's bytes (the samples are None on a cache hit: the file was not parsed)."""
    if cache is None:
        return _check_file(path, meta, limit)
    digest = hashlib.sha256(rules.encode())
    digest.update(path.read_bytes())
    key = digest.hexdigest()
    entry = cache / key[:2] / f"{key}.json"
    name = str(path)
    try:
        stored = json.loads(entry.read_text(encoding="utf-8"))
        return {kind: [m.replace(_FILE, name) for m in stored[kind]] for kind in stored}, None
    except (OSError, ValueError, KeyError, TypeError):
        pass  # not cached yet, or an unreadable entry: check again
    result, data = _check_file(path, meta, limit)
    generic = {kind: [m.replace(name, _FILE) for m in result[kind]] for kind in result}
    entry.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    write_text_atomic(json.dumps(generic), entry)
    return result, data


def check_dataset(
    folder: str | os.PathLike,
    *,
    cache_dir: str | os.PathLike | None = None,
    limit: int = MAX_PROBLEMS,
    keep_data: bool = False,
) -> DatasetCheck:
    """Check a measured dataset, its metadata and every shot file it lists: its problems
    and channel faults (a :class:`DatasetCheck`, empty when it is good).

    Parameters
    ----------
    folder : path
        Dataset folder (``data/README.md`` format).
    cache_dir : path, optional
        Folder of the verdict cache, made private (0700) if missing; one folder per
        version of this code (its verdicts are not keyed by the code). None checks
        every file.
    limit : int
        Stop after this many problems (the dataset is bad either way).
    keep_data : bool
        Keep the samples of the shot files parsed (``DatasetCheck.data``).

    Raises
    ------
    MeasuredDataError
        When ``metadata.yaml`` itself is missing or wrong (every problem listed):
        without it the shot files cannot be checked.
    """
    folder = Path(folder)
    meta = read_metadata(folder)
    rules = _rules(meta)
    cache = None if cache_dir is None else Path(cache_dir)
    if cache is not None:
        cache.mkdir(mode=0o700, parents=True, exist_ok=True)
    problems: list[str] = []
    faults: dict[int, tuple[str, ...]] = {}
    kept: dict[int, np.ndarray] = {}
    for shot, entry in enumerate(meta.shots):
        path = folder / entry.file
        if not path.is_file():
            at = f" line {entry.line}" if entry.line is not None else ""
            problems.append(
                f"{folder / METADATA_FILE}{at}: shots[{shot}].file names a missing file "
                f"{entry.file!r}"
            )
        else:
            result, data = _cached_check(path, meta, rules, cache, limit)
            problems += result["problems"]
            if result["faults"]:
                faults[shot] = tuple(result["faults"])
            if keep_data and data is not None:
                kept[shot] = data
    return DatasetCheck(str(folder), meta, tuple(problems), faults, kept)
