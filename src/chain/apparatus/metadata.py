"""``metadata.yaml`` of a measured dataset: read, validate, write.

The format's specification is the JSON schema ``metadata.schema.yaml`` shipped next to
this module (package data, so that the library finds it wherever it is installed;
``workflow/schemas/metadata.schema.yaml`` links to it). :func:`parse_metadata` validates
a parsed mapping against it with :mod:`jsonschema`, then checks what a schema cannot say
(sensor beads inside the chain and increasing, one sensitivity per sensor, each file
once and inside the folder, the amplitude groups). Every problem becomes one line
"file line N: key: what is wrong": the line is found from the jsonschema error's
``absolute_path`` in the YAML text.
"""

from __future__ import annotations

import functools
import itertools
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import jsonschema
import numpy as np
import yaml

from chain.apparatus.measured_format import (
    FORMAT_NAME,
    METADATA_FILE,
    STANDARD_GRAVITY,
    MeasuredDataError,
    problem_list,
)
from chain.apparatus.yaml_text import load_yaml, yaml_lines
from chain.atomic import write_text_atomic
from chain.errors import key_label, nonfinite_paths

#: File name of the schema, package data of chain.apparatus.
SCHEMA_FILE = "metadata.schema.yaml"


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
    samples : int or None
        Samples per shot file, when the metadata gives it.
    adc_range_V : float or None
        Digitiser half span, V, when given (saturation check).
    adc_bits : int or None
        Digitiser resolution, bits, when given.
    """

    name: str | None
    n_beads: int
    sensor_beads: tuple[int, ...]
    sensitivity_mV_per_N: tuple[float, ...]
    sampling_interval_s: float
    shots: tuple[ShotEntry, ...]
    description: str = ""
    samples: int | None = None
    adc_range_V: float | None = None
    adc_bits: int | None = None


# ----------------------------------------------------------------------------- messages


class _Messages:
    """Collects "file line N: key: what is wrong" lines, in the order of the file."""

    def __init__(self, where: str, lines: Mapping[tuple, int]):
        self.where = where
        self.lines = lines
        self.found: list[tuple[int, str]] = []

    def line_of(self, path: tuple) -> int | None:
        for cut in range(len(path), -1, -1):
            line = self.lines.get(tuple(path[:cut]))
            if line is not None:
                return line
        return None

    def add(self, path, message: str) -> None:
        path = tuple(path)
        line = self.line_of(path)
        at = f" line {line}" if line is not None else ""
        label = key_label(path) if path else ""
        text = f"{self.where}{at}: {label}{': ' if label else ''}{message}"
        if all(text != known for _, known in self.found):
            self.found.append((line or 0, text))

    def raise_any(self) -> None:
        if self.found:
            ordered = [text for _, text in sorted(self.found, key=lambda item: item[0])]
            raise MeasuredDataError(problem_list(ordered))


_NOUNS = {
    "integer": "an integer",
    "number": "a number",
    "string": "a string",
    "array": "a list",
    "object": "a mapping",
}


def _schema_message(error: jsonschema.ValidationError) -> tuple[tuple, str]:
    """Path and today's wording of one jsonschema error."""
    path = tuple(error.absolute_path)
    value, kind, limit = error.instance, error.validator, error.validator_value
    expected = error.schema.get("x-expected") if isinstance(error.schema, Mapping) else None
    if kind == "required":
        missing = [key for key in limit if key not in value]
        return path, f"missing keys {missing}"
    if kind == "additionalProperties":
        allowed = list(error.schema.get("properties", {}))
        unknown = [key for key in value if key not in allowed]
        return (*path, unknown[0]), f"unknown key (allowed: {', '.join(allowed)})"
    if kind == "type":
        types = [limit] if isinstance(limit, str) else limit
        noun = expected or " or ".join(_NOUNS.get(t, t) for t in types)
        return path, f"must be {noun}, got {value!r}"
    if kind == "exclusiveMinimum" and limit == 0:
        return path, f"must be a positive finite number, got {value!r}"
    if kind in ("minimum", "exclusiveMinimum", "maximum"):
        relation = {"minimum": ">=", "exclusiveMinimum": ">", "maximum": "<="}[kind]
        return path, f"must be {relation} {limit}, got {value!r}"
    if kind == "enum":
        return path, f"must be one of {list(limit)}, got {value!r}"
    if kind == "const":
        return path, f"must be {limit!r}, got {value!r}"
    if kind in ("minItems", "minLength", "pattern") and expected:
        return path, f"must be {expected}, got {value!r}"
    return path, error.message


@functools.cache
def metadata_validator() -> jsonschema.protocols.Validator:
    """The jsonschema validator of ``metadata.schema.yaml`` (read once)."""
    text = resources.files("chain.apparatus").joinpath(SCHEMA_FILE).read_text(encoding="utf-8")
    schema = yaml.safe_load(text)
    cls = jsonschema.validators.validator_for(schema)
    cls.check_schema(schema)
    return cls(schema)


# ----------------------------------------------------------------------------- checks


def _check_beads(messages: _Messages, mapping: Mapping) -> None:
    n_beads, beads = mapping["N"], mapping["sensor_beads"]
    for i, bead in enumerate(beads):
        if bead > n_beads:
            messages.add(("sensor_beads", i), f"bead {bead} is outside the chain 1..{n_beads}")
    if any(a >= b for a, b in itertools.pairwise(beads)):
        messages.add(("sensor_beads",), f"must be strictly increasing (S1 first), got {beads}")
    sensitivity = mapping["sensitivity_mV_per_N"]
    if isinstance(sensitivity, list) and len(sensitivity) != len(beads):
        messages.add(
            ("sensitivity_mV_per_N",),
            f"needs one value per sensor ({len(beads)}), got {len(sensitivity)}",
        )


def _check_shots(messages: _Messages, shots: list) -> None:
    seen: dict[str, int] = {}
    for i, entry in enumerate(shots):
        path = ("shots", i)
        file = entry["file"]
        if Path(file).is_absolute() or ".." in Path(file).parts:
            messages.add((*path, "file"), f"must be relative to the dataset, got {file!r}")
        if file in seen:
            messages.add((*path, "file"), f"{file!r} is already listed as shots[{seen[file]}]")
        seen.setdefault(file, i)
        if "drop_height_m" in entry and "impact_speed_m_s" in entry:
            messages.add(path, "give drop_height_m or impact_speed_m_s, not both")
    labels = [entry.get("amplitude") for entry in shots]
    given = [label is not None for label in labels]
    if any(given) and not all(given):
        messages.add(
            ("shots", given.index(False)), "amplitude is given for some shots but not this one"
        )
    elif all(given) and len({isinstance(label, int) for label in labels}) > 1:
        messages.add(("shots",), "amplitude: use integer indices or labels, not both")
    elif not any(given):
        for i, entry in enumerate(shots):
            if "drop_height_m" not in entry and "impact_speed_m_s" not in entry:
                messages.add(("shots", i), "needs amplitude, drop_height_m or impact_speed_m_s")


def _speed(entry: Mapping) -> float:
    if "drop_height_m" in entry:
        return float(impact_speed_from_drop_height(entry["drop_height_m"]))
    return float(entry.get("impact_speed_m_s", math.nan))


def _groups(shots: list) -> list[int]:
    """Amplitude group of each shot (rules in :func:`parse_metadata`)."""
    labels = [entry.get("amplitude") for entry in shots]
    if all(isinstance(label, int) for label in labels):
        return [int(label) for label in labels]
    if all(isinstance(label, str) for label in labels):
        index = {label: i for i, label in enumerate(dict.fromkeys(labels))}
        return [index[label] for label in labels]
    ranks = {speed: i for i, speed in enumerate(sorted({_speed(e) for e in shots}))}
    return [ranks[_speed(entry)] for entry in shots]


def parse_metadata(
    mapping, where: str = METADATA_FILE, lines: Mapping[tuple, int] | None = None
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
        Listing every problem found, one line each (schema problems first; the
        relations between keys are checked only on a schema-valid mapping).
    """
    messages = _Messages(where, lines or {})
    if not isinstance(mapping, Mapping):
        messages.add((), f"must be a YAML mapping of keys, got {type(mapping).__name__}")
        messages.raise_any()
    for error in metadata_validator().iter_errors(mapping):
        messages.add(*_schema_message(error))
    for path, number in nonfinite_paths(dict(mapping)):
        messages.add(path, f"must be a finite number, got {number!r}")
    messages.raise_any()
    _check_beads(messages, mapping)
    _check_shots(messages, mapping["shots"])
    messages.raise_any()
    return _typed(mapping, messages)


def _typed(mapping: Mapping, messages: _Messages) -> DatasetMetadata:
    beads = tuple(int(b) for b in mapping["sensor_beads"])
    sensitivity = mapping["sensitivity_mV_per_N"]
    if not isinstance(sensitivity, list):
        sensitivity = [sensitivity] * len(beads)
    shots = mapping["shots"]
    entries = tuple(
        ShotEntry(
            file=entry["file"],
            kind=entry["kind"],
            amplitude=group,
            impact_speed_m_s=_speed(entry),
            line=messages.line_of(("shots", i)) if messages.lines else None,
        )
        for i, (entry, group) in enumerate(zip(shots, _groups(shots)))
    )
    optional = {key: mapping.get(key) for key in ("samples", "adc_range_V", "adc_bits")}
    return DatasetMetadata(
        name=mapping.get("name"),
        n_beads=int(mapping["N"]),
        sensor_beads=beads,
        sensitivity_mV_per_N=tuple(float(s) for s in sensitivity),
        sampling_interval_s=float(mapping["sampling_interval_s"]),
        shots=entries,
        description=mapping.get("description", ""),
        samples=None if optional["samples"] is None else int(optional["samples"]),
        adc_range_V=None if optional["adc_range_V"] is None else float(optional["adc_range_V"]),
        adc_bits=None if optional["adc_bits"] is None else int(optional["adc_bits"]),
    )


def read_metadata(folder: str | os.PathLike) -> DatasetMetadata:
    """Read and check ``<folder>/metadata.yaml`` of a dataset folder
    (:class:`MeasuredDataError` when it is missing or wrong)."""
    path = Path(folder) / METADATA_FILE
    if not Path(folder).is_dir():
        raise MeasuredDataError(f"{folder}: no such dataset folder")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MeasuredDataError(f"{path}: no such file (every dataset needs one)") from None
    except UnicodeDecodeError as error:
        raise MeasuredDataError(f"{path}: not UTF-8 text ({error})") from None
    mapping = load_yaml(text, str(path))
    if mapping is None:
        raise MeasuredDataError(f"{path}: empty file")
    return parse_metadata(mapping, where=str(path), lines=yaml_lines(text))


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


__all__ = [
    "FORMAT_NAME",
    "DatasetMetadata",
    "ShotEntry",
    "impact_speed_from_drop_height",
    "load_yaml",
    "metadata_validator",
    "parse_metadata",
    "read_metadata",
    "write_metadata",
    "yaml_lines",
]
