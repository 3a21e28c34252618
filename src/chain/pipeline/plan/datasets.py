"""The experiment's parts (chains and their datasets) and labels, and the measured
datasets a config uses, checked before any job runs.

Every problem of every shot file is listed at once (file, line, column, what was
expected). With ``experiment.bad_channels: skip``, shots with a dead or saturated channel
are left out, and listed as rejected (:func:`skipped_shot_rows`). The verdicts are cached
in a folder named by a digest of the check's code (:data:`DEFAULT_CACHE`).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from chain.analysis.selection import SELECTION_COLUMNS
from chain.apparatus.dataset_check import DatasetCheck, check_dataset
from chain.apparatus.measured import MeasuredDataError, read_metadata, usable_shots
from chain.errors import ConfigError, key_label
from chain.labels import SKIPPED_REASON, VIRTUAL_LABEL, VIRTUAL_SERIES
from chain.pipeline.plan.code import module_sources

#: The module whose verdicts are cached, and the package it is in.
CHECK_MODULE = "chain.apparatus.dataset_check"
PACKAGE_DIR = Path(__file__).resolve().parents[2]


def check_code_digest(package_dir: str | os.PathLike = PACKAGE_DIR) -> str:
    """SHA-256 (hex) of the code of the dataset check: every file of the package
    ``package_dir`` (the ``chain`` folder) that importing :data:`CHECK_MODULE` runs, each
    with its path in the package."""
    digest = hashlib.sha256()
    for path in module_sources(CHECK_MODULE, package_dir):
        name = path.relative_to(Path(package_dir).resolve()).as_posix()
        digest.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


#: Where the pipeline keeps the dataset check's verdicts, a folder per version of its code.
DEFAULT_CACHE = Path(".snakemake") / "hertzchain" / f"dataset-check-{check_code_digest()[:16]}"

#: Series names usable in file names (experiment/<name>_N<N>_traces.csv).
SERIES_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]*$")


def _fail(path, message: str):
    raise ConfigError(f"config key {key_label(path)!r}: {message}")


@dataclass(frozen=True)
class ExperimentPart:
    """One chain of the experiment: where its traces come from."""

    #: Series name (the ``model`` column; chains of one name are pooled in the fits).
    name: str
    n_beads: int
    #: Sensor beads, S1 first.
    sensor_beads: tuple[int, ...]
    #: The measured dataset folder; None for the virtual experiment (a pipeline output).
    folder: str | None = None
    #: ``metadata.yaml`` and the shot files of a measured dataset (empty for virtual).
    files: tuple[str, ...] = ()
    #: Whether the traces come from the virtual experiment (a model, not data), a
    #: measured-format dataset that it wrote included.
    virtual: bool = True


def experiment_parts(config: Mapping, root: str | os.PathLike = ".") -> list[ExperimentPart]:
    """The chains of the experiment of ``config`` (checked): none with ``experiment.source:
    none``, one per configured chain for the virtual experiment, one per measured dataset
    (read from its metadata; relative folders start from ``root``); ConfigError naming
    ``experiment.datasets[i]`` when a dataset's metadata is missing or wrong, its name
    unusable in file names, or its name and N those of another."""
    experiment = config.get("experiment", {})
    source = experiment.get("source", "none")
    name = experiment.get("name")
    if source == "virtual":
        return [
            ExperimentPart(name or VIRTUAL_SERIES, int(c["N"]), tuple(c["sensors"]))
            for c in config["chains"]
        ]
    if source != "measured":
        return []
    parts: list[ExperimentPart] = []
    seen: dict[tuple[str, int], int] = {}
    for i, folder in enumerate(experiment.get("datasets", [])):
        path = ["experiment", "datasets", i]
        where = Path(root) / folder  # an absolute folder as it is
        try:
            meta = read_metadata(where)
        except MeasuredDataError as error:
            _fail(path, f"{error}")
        series = name or meta.name or where.resolve().name
        if not SERIES_NAME.match(series):
            _fail(
                path,
                f"dataset name {series!r} (metadata name, else folder name) is not usable "
                "in file names; allowed: letters, digits, '_', '-', starting with a "
                "letter; set experiment.name",
            )
        key = (series, meta.n_beads)
        if key in seen:
            _fail(
                path,
                f"gives the series {series!r} with N = {meta.n_beads} again (as "
                f"experiment.datasets[{seen[key]}]); allowed: one dataset per name and N",
            )
        seen[key] = i
        listed = ("metadata.yaml", *(shot.file for shot in meta.shots))
        files = tuple(str(Path(folder) / file) for file in listed)
        virtual = VIRTUAL_LABEL in (meta.description or "")
        beads = tuple(meta.sensor_beads)
        parts.append(ExperimentPart(series, meta.n_beads, beads, str(folder), files, virtual))
    return parts


def experiment_label(parts: Sequence[ExperimentPart]) -> str:
    """How figures and the summary name the series of ``parts`` (:func:`experiment_parts`):
    ``"virtual experiment (model)"``, ``"measured (<names>)"``, or ``"virtual experiment
    (model): <names>"`` for a dataset the virtual experiment wrote (still not data)."""
    if not parts:
        return "experiment"
    if all(part.folder is None for part in parts):
        return VIRTUAL_LABEL
    names = ", ".join(dict.fromkeys(part.name for part in parts))
    if all(part.virtual for part in parts):
        return f"{VIRTUAL_LABEL}: {names}"
    return f"measured ({names})"


def bad_channel_policy(config: Mapping) -> str:
    """``experiment.bad_channels`` of a config (``stop`` or ``skip``)."""
    return config.get("experiment", {}).get("bad_channels", "stop")


def check_experiment_datasets(
    config: Mapping,
    parts: Sequence[ExperimentPart],
    root: str | os.PathLike = ".",
    cache_dir: str | os.PathLike | None = DEFAULT_CACHE,
) -> None:
    """Check every measured dataset of ``parts`` (:func:`experiment_parts` of the checked
    ``config``; relative folders start from ``root``); ConfigError listing all problems.
    ``cache_dir`` keeps the verdicts (relative to ``root``; private, 0700; the folders of
    other versions of the check's code beside it are removed); None checks every file."""
    policy = bad_channel_policy(config)
    cache = None if cache_dir is None else Path(root) / cache_dir
    for old in [] if cache is None else cache.parent.glob("dataset-check*"):
        if old != cache and old.is_dir():
            shutil.rmtree(old, ignore_errors=True)
    messages = []
    for part in parts:
        try:
            if part.folder is not None:
                usable_shots(check_dataset(Path(root) / part.folder, cache_dir=cache), policy)
        except MeasuredDataError as error:
            messages.append(str(error))
    if messages:
        raise ConfigError(
            f"config key 'experiment.datasets': {len(messages)} of {len(parts)} datasets cannot be "
            "used (data/README.md; every problem below, up to 20 per dataset):\n"
            + "\n".join(messages)
        )


def skipped_shot_rows(check: DatasetCheck, name: str) -> pd.DataFrame:
    """Selection rows (:data:`chain.analysis.selection.SELECTION_COLUMNS`) of the shots a
    dataset's ``check`` (:func:`~chain.apparatus.dataset_check.check_dataset`) left out for
    a dead or saturated channel, the channel as the reason; ``name``: its series."""
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
