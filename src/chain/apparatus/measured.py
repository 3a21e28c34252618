"""The lab's measured-trace format (``data/README.md``) and its loader.

A *dataset* is one folder holding one CSV file per shot (oscilloscope export: time
in seconds, one voltage column per sensor) and a ``metadata.yaml`` that says what
the shots are::

    data/<dataset>/
        metadata.yaml
        shot_0000.csv        t_s,bead9_V,bead17_V
        ...

:func:`load_dataset` checks everything and returns a trace table
(:mod:`chain.traces`, source ``experiment``) in newtons. Any defect raises
:class:`MeasuredDataError` naming the file and, where it applies, the line a person
sees in an editor (the CSV header is line 1). :func:`write_shot_csv` and
:func:`write_metadata` write the same format (the virtual experiment uses them).
"""

from __future__ import annotations

import io
import itertools
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from chain.apparatus.acquisition import volts_to_newtons
from chain.atomic import write_text_atomic
from chain.errors import key_label
from chain.traces import KINDS, META_COLUMNS, sensor_column, validate_traces

#: Name of the metadata file of a dataset.
METADATA_FILE = "metadata.yaml"

#: Value of the optional ``format`` key (bumped if the format ever changes).
FORMAT_NAME = "hertzchain-measured-traces/1"

#: Name of the time column of a shot file (seconds).
TIME_COLUMN = "t_s"

#: Standard gravity used to turn a drop height into an impact speed, m/s^2.
STANDARD_GRAVITY = 9.80665

#: Largest deviation of a time step from ``sampling_interval_s``, as a fraction of it.
#: Generous enough for times exported with 6 significant digits.
TIME_STEP_TOLERANCE = 0.01

REQUIRED_KEYS = ("N", "sensor_beads", "sensitivity_mV_per_N", "sampling_interval_s", "shots")
OPTIONAL_KEYS = ("format", "name", "description", "apparatus")
SHOT_REQUIRED_KEYS = ("file", "kind")
SHOT_OPTIONAL_KEYS = ("amplitude", "drop_height_m", "impact_speed_m_s", "comment")


class MeasuredDataError(ValueError):
    """A measured dataset does not follow the format; the message names file and line."""


def voltage_column(bead: int) -> str:
    """Header of the voltage column of the sensor in bead ``bead`` (1..N), V."""
    return f"bead{int(bead)}_V"


def impact_speed_from_drop_height(height_m, gravity: float = STANDARD_GRAVITY):
    """Free-fall impact speed sqrt(2 g h), m/s.

    Parameters
    ----------
    height_m : float or array
        Drop height, m.
    gravity : float
        Gravitational acceleration, m/s^2.
    """
    return np.sqrt(2.0 * gravity * np.asarray(height_m, dtype=float))


@dataclass(frozen=True)
class ShotEntry:
    """One shot of a dataset, as listed in ``metadata.yaml``.

    Attributes
    ----------
    file : str
        Shot CSV, relative to the dataset folder.
    kind : str
        ``collision`` or ``reference``.
    amplitude : int
        Index of the nominal-amplitude group (see :func:`parse_metadata`).
    impact_speed_m_s : float
        Nominal striker impact speed, m/s (from ``drop_height_m`` or
        ``impact_speed_m_s``); NaN when not given.
    line : int or None
        Line of the entry in ``metadata.yaml`` (for messages), if known.
    """

    file: str
    kind: str
    amplitude: int
    impact_speed_m_s: float
    line: int | None = None


@dataclass(frozen=True)
class DatasetMetadata:
    """The checked content of a ``metadata.yaml``.

    Attributes
    ----------
    name : str or None
        Dataset name from the ``name`` key.
    n_beads : int
        Number of beads N.
    sensor_beads : tuple of int
        Sensor beads, S1 first (strictly increasing).
    sensitivity_mV_per_N : tuple of float
        Sensitivity of each sensor, mV/N.
    sampling_interval_s : float
        Sampling interval, s.
    shots : tuple of ShotEntry
    description : str
    """

    name: str | None
    n_beads: int
    sensor_beads: tuple[int, ...]
    sensitivity_mV_per_N: tuple[float, ...]
    sampling_interval_s: float
    shots: tuple[ShotEntry, ...]
    description: str = ""


# ----------------------------------------------------------------------------- metadata


def _yaml_lines(text: str) -> dict[tuple, int]:
    """1-based line of every node of a YAML document, keyed by its path (keys, indices)."""
    lines: dict[tuple, int] = {}

    def walk(node, path):
        lines[path] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                lines[(*path, key.value)] = key.start_mark.line + 1
                walk(value, (*path, key.value))
        elif isinstance(node, yaml.SequenceNode):
            for index, item in enumerate(node.value):
                walk(item, (*path, index))

    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError:
        return lines
    if root is not None:
        walk(root, ())
    return lines


class _Checker:
    """Type checks that name the metadata file, the line and the key."""

    def __init__(self, where: str, lines: dict[tuple, int]):
        self.where = where
        self.lines = lines

    def error(self, path: tuple, message: str) -> MeasuredDataError:
        line = self.lines.get(path)
        for cut in range(len(path), 0, -1):
            if line is not None:
                break
            line = self.lines.get(path[:cut])
        at = f" line {line}" if line is not None else ""
        label = key_label(path)
        return MeasuredDataError(f"{self.where}{at}: {label}{': ' if label else ''}{message}")

    def integer(self, path, value, minimum=None) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(path, f"must be an integer, got {value!r}")
        if minimum is not None and value < minimum:
            raise self.error(path, f"must be >= {minimum}, got {value}")
        return int(value)

    def positive(self, path, value) -> float:
        # PyYAML (YAML 1.1) reads 1e-6 without a dot as a string: accept numeric strings.
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise self.error(path, f"must be a number, got {value!r}") from None
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(path, f"must be a number, got {value!r}")
        if not math.isfinite(value) or value <= 0:
            raise self.error(path, f"must be a positive finite number, got {value!r}")
        return float(value)

    def string(self, path, value) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.error(path, f"must be a non-empty string, got {value!r}")
        return value


def parse_metadata(
    mapping, where: str = METADATA_FILE, lines: dict[tuple, int] | None = None
) -> DatasetMetadata:
    """Check a metadata mapping (the parsed ``metadata.yaml``) and return it typed.

    Amplitude groups: when every shot has ``amplitude``, integers are used as given
    and labels (strings) are numbered 0, 1, ... in order of first appearance; when no
    shot has it, shots are grouped by nominal impact speed (from ``drop_height_m`` or
    ``impact_speed_m_s``), numbered from the slowest.

    Parameters
    ----------
    mapping : dict
        Parsed YAML.
    where : str
        File name used in messages.
    lines : dict, optional
        Line of each key path (from the YAML text), for messages.

    Raises
    ------
    MeasuredDataError
    """
    check = _Checker(where, lines or {})
    if not isinstance(mapping, Mapping):
        raise check.error((), f"must be a YAML mapping of keys, got {type(mapping).__name__}")
    missing = [key for key in REQUIRED_KEYS if key not in mapping]
    if missing:
        raise check.error((), f"missing keys {missing}")
    unknown = [key for key in mapping if key not in REQUIRED_KEYS + OPTIONAL_KEYS]
    if unknown:
        raise check.error(
            (unknown[0],),
            f"unknown key (allowed: {', '.join(REQUIRED_KEYS + OPTIONAL_KEYS)})",
        )
    if "format" in mapping and mapping["format"] != FORMAT_NAME:
        raise check.error(("format",), f"must be {FORMAT_NAME!r}, got {mapping['format']!r}")
    name = check.string(("name",), mapping["name"]) if "name" in mapping else None
    description = mapping.get("description", "")
    if not isinstance(description, str):
        raise check.error(("description",), f"must be a string, got {description!r}")
    if "apparatus" in mapping and not isinstance(mapping["apparatus"], Mapping):
        raise check.error(("apparatus",), "must be a mapping (free-form notes)")

    n_beads = check.integer(("N",), mapping["N"], minimum=2)
    beads_value = mapping["sensor_beads"]
    if not isinstance(beads_value, list) or not beads_value:
        raise check.error(("sensor_beads",), f"must be a list of bead numbers, got {beads_value!r}")
    beads = tuple(
        check.integer(("sensor_beads", i), b, minimum=1) for i, b in enumerate(beads_value)
    )
    for i, bead in enumerate(beads):
        if bead > n_beads:
            raise check.error(("sensor_beads", i), f"bead {bead} is outside the chain 1..{n_beads}")
    if any(a >= b for a, b in itertools.pairwise(beads)):
        raise check.error(
            ("sensor_beads",), f"must be strictly increasing (S1 first), got {list(beads)}"
        )
    sens_value = mapping["sensitivity_mV_per_N"]
    if isinstance(sens_value, list):
        if len(sens_value) != len(beads):
            raise check.error(
                ("sensitivity_mV_per_N",),
                f"needs one value per sensor ({len(beads)}), got {len(sens_value)}",
            )
        sensitivity = tuple(
            check.positive(("sensitivity_mV_per_N", i), s) for i, s in enumerate(sens_value)
        )
    else:
        sensitivity = (check.positive(("sensitivity_mV_per_N",), sens_value),) * len(beads)
    interval = check.positive(("sampling_interval_s",), mapping["sampling_interval_s"])

    shots_value = mapping["shots"]
    if not isinstance(shots_value, list) or not shots_value:
        raise check.error(("shots",), "must be a non-empty list of shot entries")
    raw = []
    seen_files: dict[str, int] = {}
    for i, entry in enumerate(shots_value):
        path = ("shots", i)
        if not isinstance(entry, Mapping):
            raise check.error(path, f"must be a mapping with file and kind, got {entry!r}")
        missing = [key for key in SHOT_REQUIRED_KEYS if key not in entry]
        if missing:
            raise check.error(path, f"missing keys {missing}")
        unknown = [key for key in entry if key not in SHOT_REQUIRED_KEYS + SHOT_OPTIONAL_KEYS]
        if unknown:
            allowed = ", ".join(SHOT_REQUIRED_KEYS + SHOT_OPTIONAL_KEYS)
            raise check.error((*path, unknown[0]), f"unknown key (allowed: {allowed})")
        file = check.string((*path, "file"), entry["file"])
        if Path(file).is_absolute() or ".." in Path(file).parts:
            raise check.error((*path, "file"), f"must be relative to the dataset, got {file!r}")
        if file in seen_files:
            raise check.error(
                (*path, "file"), f"{file!r} is already listed as shots[{seen_files[file]}]"
            )
        seen_files[file] = i
        kind = entry["kind"]
        if kind not in KINDS:
            raise check.error((*path, "kind"), f"must be one of {list(KINDS)}, got {kind!r}")
        if "drop_height_m" in entry and "impact_speed_m_s" in entry:
            raise check.error(path, "give drop_height_m or impact_speed_m_s, not both")
        if "drop_height_m" in entry:
            height = check.positive((*path, "drop_height_m"), entry["drop_height_m"])
            speed = float(impact_speed_from_drop_height(height))
        elif "impact_speed_m_s" in entry:
            speed = check.positive((*path, "impact_speed_m_s"), entry["impact_speed_m_s"])
        else:
            speed = math.nan
        label = entry.get("amplitude")
        if label is not None and (
            isinstance(label, bool) or not isinstance(label, int | str) or label == ""
        ):
            raise check.error(
                (*path, "amplitude"), f"must be an integer index or a label, got {label!r}"
            )
        if isinstance(label, int) and label < 0:
            raise check.error((*path, "amplitude"), f"must be >= 0, got {label}")
        if "comment" in entry and not isinstance(entry["comment"], str):
            raise check.error((*path, "comment"), "must be a string")
        raw.append((file, kind, label, speed, check.lines.get(path)))

    labels = [r[2] for r in raw]
    if all(label is not None for label in labels):
        if all(isinstance(label, int) for label in labels):
            index = {label: label for label in labels}
        elif all(isinstance(label, str) for label in labels):
            index = {label: i for i, label in enumerate(dict.fromkeys(labels))}
        else:
            raise check.error(("shots",), "amplitude: use integer indices or labels, not both")
        groups = [index[label] for label in labels]
    elif any(label is not None for label in labels):
        first = next(i for i, label in enumerate(labels) if label is None)
        raise check.error(("shots", first), "amplitude is given for some shots but not this one")
    else:
        for i, r in enumerate(raw):
            if math.isnan(r[3]):
                raise check.error(
                    ("shots", i), "needs amplitude, drop_height_m or impact_speed_m_s"
                )
        ranks = {speed: i for i, speed in enumerate(sorted({r[3] for r in raw}))}
        groups = [ranks[r[3]] for r in raw]
    shots = tuple(
        ShotEntry(file=r[0], kind=r[1], amplitude=g, impact_speed_m_s=r[3], line=r[4])
        for r, g in zip(raw, groups)
    )
    return DatasetMetadata(
        name=name,
        n_beads=n_beads,
        sensor_beads=beads,
        sensitivity_mV_per_N=sensitivity,
        sampling_interval_s=interval,
        shots=shots,
        description=description,
    )


def read_metadata(folder: str | os.PathLike) -> DatasetMetadata:
    """Read and check ``<folder>/metadata.yaml``.

    Parameters
    ----------
    folder : path
        Dataset folder.

    Raises
    ------
    MeasuredDataError
    """
    path = Path(folder) / METADATA_FILE
    if not Path(folder).is_dir():
        raise MeasuredDataError(f"{folder}: no such dataset folder")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MeasuredDataError(f"{path}: no such file (every dataset needs one)") from None
    except UnicodeDecodeError as error:
        raise MeasuredDataError(f"{path}: not UTF-8 text ({error})") from None
    try:
        mapping = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        at = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(error, "problem", None) or str(error)
        raise MeasuredDataError(f"{path}{at}: not valid YAML ({problem})") from None
    if mapping is None:
        raise MeasuredDataError(f"{path}: empty file")
    return parse_metadata(mapping, where=str(path), lines=_yaml_lines(text))


# ----------------------------------------------------------------------------- shot files


def read_shot_csv(
    path: str | os.PathLike,
    sensor_beads: Sequence[int],
    sampling_interval_s: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Read and check one shot file.

    Parameters
    ----------
    path : path
        Shot CSV: header ``t_s,bead<n>_V,...`` (sensors in ``sensor_beads`` order),
        then one sample per line.
    sensor_beads : sequence of int
        Sensor beads the header must name, S1 first.
    sampling_interval_s : float, optional
        Expected time step, s; every step must match it within
        :data:`TIME_STEP_TOLERANCE`. Without it the steps must merely be even.

    Returns
    -------
    time : (S,) s
    volts : (n_sensors, S) V

    Raises
    ------
    MeasuredDataError
        Naming the file and the line (header = line 1).
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise MeasuredDataError(f"{path}: no such file") from None
    except UnicodeDecodeError as error:
        raise MeasuredDataError(f"{path}: not a text CSV file ({error})") from None
    lines = text.splitlines()
    # Blank lines at the end are harmless (editors add them); elsewhere they are errors.
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise MeasuredDataError(f"{path}: empty file")
    expected = [TIME_COLUMN] + [voltage_column(b) for b in sensor_beads]
    header = [name.strip() for name in lines[0].split(",")]
    missing = [name for name in expected if name not in header]
    if missing:
        raise MeasuredDataError(
            f"{path} line 1: missing columns {missing} (expected header {','.join(expected)})"
        )
    extra = [name for name in header if name not in expected]
    if extra:
        raise MeasuredDataError(
            f"{path} line 1: unexpected columns {extra} (expected header {','.join(expected)})"
        )
    if header != expected:
        raise MeasuredDataError(
            f"{path} line 1: columns must be in the order {','.join(expected)}, got "
            f"{','.join(header)}"
        )
    body = lines[1:]
    if len(body) < 3:
        raise MeasuredDataError(f"{path}: {len(body)} data rows, need at least 3 (truncated file?)")
    rows = [line.split(",") for line in body]
    width = len(expected)
    for number, row in enumerate(rows, start=2):
        if len(row) != width:
            hint = " (truncated file?)" if number == len(rows) + 1 else ""
            raise MeasuredDataError(
                f"{path} line {number}: {len(row)} fields, expected {width}{hint}"
            )
    try:
        data = np.array(rows, dtype=float)
    except ValueError:
        data = None
    if data is None or not np.all(np.isfinite(data)):
        for number, row in enumerate(rows, start=2):
            for column, field in zip(expected, row):
                if not field.strip():
                    raise MeasuredDataError(
                        f"{path} line {number}: column {column}: missing value (empty field)"
                    )
                try:
                    value = float(field)
                except ValueError:
                    raise MeasuredDataError(
                        f"{path} line {number}: column {column}: {field.strip()!r} is not a number"
                    ) from None
                if not math.isfinite(value):
                    raise MeasuredDataError(
                        f"{path} line {number}: column {column}: missing or non-finite value "
                        f"{field.strip()!r}"
                    )
        # Only reached when numpy rejects a field that Python's float accepts.
        data = np.array([[float(field) for field in row] for row in rows])
    time = data[:, 0]
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        number = int(bad[0]) + 3  # step i joins data rows i and i+1, i.e. lines i+2, i+3
        raise MeasuredDataError(
            f"{path} line {number}: time {body[bad[0] + 1].split(',')[0].strip()} s does not "
            f"increase (previous sample {body[bad[0]].split(',')[0].strip()} s)"
        )
    nominal = float(np.median(step)) if sampling_interval_s is None else sampling_interval_s
    bad = np.flatnonzero(np.abs(step - nominal) > TIME_STEP_TOLERANCE * nominal)
    if bad.size:
        number = int(bad[0]) + 3
        what = "sampling_interval_s" if sampling_interval_s is not None else "the median step"
        raise MeasuredDataError(
            f"{path} line {number}: time step {step[bad[0]]:.6g} s differs from {what} "
            f"{nominal:.6g} s (uneven sampling, or time not in seconds)"
        )
    return time, data[:, 1:].T.copy()


def load_dataset(folder: str | os.PathLike, name: str | None = None) -> pd.DataFrame:
    """Load a measured dataset as a trace table in newtons.

    Parameters
    ----------
    folder : path
        Dataset folder with ``metadata.yaml`` and the shot CSV files.
    name : str, optional
        Value of the ``model`` column; default the metadata ``name``, else the folder
        name.

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
        Naming the file (and line) at fault.
    """
    folder = Path(folder)
    meta = read_metadata(folder)
    model = name or meta.name or folder.resolve().name
    metadata_path = folder / METADATA_FILE
    tables = []
    for shot, entry in enumerate(meta.shots):
        path = folder / entry.file
        if not path.is_file():
            at = f" line {entry.line}" if entry.line is not None else ""
            raise MeasuredDataError(
                f"{metadata_path}{at}: shots[{shot}].file names a missing file {entry.file!r}"
            )
        time, volts = read_shot_csv(path, meta.sensor_beads, meta.sampling_interval_s)
        v_left = entry.impact_speed_m_s
        v_right = 0.0 if entry.kind == "reference" else entry.impact_speed_m_s
        columns = {
            sensor_column(bead): volts_to_newtons(volts[i], meta.sensitivity_mV_per_N[i])
            for i, bead in enumerate(meta.sensor_beads)
        }
        tables.append(
            pd.DataFrame(
                {
                    "source": "experiment",
                    "model": model,
                    "N": meta.n_beads,
                    "shot": shot,
                    "kind": entry.kind,
                    "amplitude": entry.amplitude,
                    "v0_left_m_s": v_left,
                    "v0_right_m_s": v_right,
                    "t_s": time,
                    **columns,
                }
            )
        )
    table = pd.concat(tables, ignore_index=True)
    table = table[list(META_COLUMNS) + [sensor_column(b) for b in meta.sensor_beads]]
    return validate_traces(table, where=str(folder))


# ----------------------------------------------------------------------------- writers


def write_shot_csv(path: str | os.PathLike, time_s, volts_V, sensor_beads: Sequence[int]) -> None:
    """Write one shot file in the measured format, atomically.

    Times are written with 10 significant digits and volts with 7 (below 1 uV), so
    the bytes depend only on the values.

    Parameters
    ----------
    path : path
        Destination CSV.
    time_s : array (S,)
        Sample times, s.
    volts_V : array (n_sensors, S)
        Sensor voltages, V, S1 first.
    sensor_beads : sequence of int
        Bead of each sensor, S1 first.
    """
    time = np.asarray(time_s, dtype=float)
    volts = np.atleast_2d(np.asarray(volts_V, dtype=float))
    if volts.shape != (len(sensor_beads), time.size):
        raise MeasuredDataError(
            f"{path}: volts must have shape ({len(sensor_beads)}, {time.size}), got {volts.shape}"
        )
    # + 0.0 turns the -0.0 of a quantised zero into 0.0, so the file never shows "-0".
    volts = volts + 0.0
    buffer = io.StringIO()
    header = ",".join([TIME_COLUMN] + [voltage_column(b) for b in sensor_beads])
    np.savetxt(
        buffer,
        np.column_stack([time, volts.T]),
        fmt=["%.10g"] + ["%.7g"] * len(sensor_beads),
        delimiter=",",
        header=header,
        comments="",
    )
    write_text_atomic(buffer.getvalue(), Path(path))


def write_metadata(folder: str | os.PathLike, mapping: Mapping) -> Path:
    """Check ``mapping`` with :func:`parse_metadata` and write it as
    ``<folder>/metadata.yaml``, atomically. Returns the file path.

    Parameters
    ----------
    folder : path
        Dataset folder.
    mapping : dict
        Metadata (plain Python types: str, int, float, list, dict).
    """
    path = Path(folder) / METADATA_FILE
    parse_metadata(mapping, where=str(path))
    text = yaml.safe_dump(
        dict(mapping), sort_keys=False, default_flow_style=None, allow_unicode=True, width=100
    )
    write_text_atomic(text, path)
    return path
