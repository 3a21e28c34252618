"""The one trace format: sampled sensor forces of a set of shots, read/write/validate.

A *trace table* is a pandas DataFrame in long form (one row per shot and sample),
written to disk as CSV. Columns:

=================  ======  ==========================================================
column             type    meaning
=================  ======  ==========================================================
``source``         str     ``simulation``, ``experiment`` or ``lammps`` (the LAMMPS engine)
``model``          str     model name (``elastic``, ``viscoelastic``...) or dataset name
``N``              int     number of beads in the chain
``shot``           int     shot id, unique within the table
``kind``           str     ``collision`` (both waves launched) or ``reference`` (left only)
``amplitude``      int     index of the nominal launch amplitude (groups shots of one amplitude)
``v0_left_m_s``    float   left launch speed (bead 1 or striker), m/s; NaN if unknown
``v0_right_m_s``   float   right launch speed, m/s (0 for a reference shot); NaN if unknown
``t_s``            float   time, s (any origin; only differences matter)
``force_bead<n>_N`` float  force read at bead n, N, one column per sensor bead, in order
=================  ======  ==========================================================

Sensors are beads 1..N, in increasing order: the first sensor column is S1 (met first
by the left-launched wave, LSTW), the last is S2. Within a shot, time is strictly
increasing and evenly sampled.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from chain.atomic import atomic_output, write_csv_atomic
from chain.errors import bead_number_problem
from chain.sampling import TIME_STEP_TOLERANCE

#: Columns that name one shot, first in every table with a row per shot.
SHOT_COLUMNS = ("source", "model", "N", "shot", "kind", "amplitude")
#: Columns every trace table has, in order, before the sensor columns.
META_COLUMNS = (*SHOT_COLUMNS, "v0_left_m_s", "v0_right_m_s", "t_s")
SOURCES = ("simulation", "experiment", "lammps")
KINDS = ("collision", "reference")
_SENSOR_COLUMN = re.compile(r"^force_bead(\d+)_N$")


class TraceFormatError(ValueError):
    """A trace table or file does not follow the trace format; the message says where."""


def sensor_column(bead: int) -> str:
    """Column name of the force read at ``bead`` (1..N), N."""
    return f"force_bead{int(bead)}_N"


def sensor_beads(table: pd.DataFrame) -> list[int]:
    """Bead numbers of the sensor columns of ``table``, in column order."""
    beads = []
    for column in table.columns:
        match = _SENSOR_COLUMN.match(str(column))
        if match:
            beads.append(int(match.group(1)))
    return beads


def validate_traces(table: pd.DataFrame, where: str = "trace table") -> pd.DataFrame:
    """Check ``table`` against the trace format; return it with canonical dtypes, or
    raise :class:`TraceFormatError` naming the column, shot or value that is wrong.

    Parameters
    ----------
    table : DataFrame
        A trace table.
    where : str
        Name used in error messages (e.g. the file path).
    """
    missing = [c for c in META_COLUMNS if c not in table.columns]
    if missing:
        raise TraceFormatError(f"{where}: missing columns {missing}")
    beads = sensor_beads(table)
    if not beads:
        raise TraceFormatError(f"{where}: no sensor column (force_bead<n>_N)")
    extra = [c for c in table.columns if c not in META_COLUMNS and not _SENSOR_COLUMN.match(c)]
    if extra:
        raise TraceFormatError(f"{where}: unexpected columns {extra}")
    if table.empty:
        raise TraceFormatError(f"{where}: no rows")
    bad_source = set(table["source"].unique()) - set(SOURCES)
    if bad_source:
        raise TraceFormatError(f"{where}: source must be one of {SOURCES}, got {bad_source}")
    bad_kind = set(table["kind"].unique()) - set(KINDS)
    if bad_kind:
        raise TraceFormatError(f"{where}: kind must be one of {KINDS}, got {bad_kind}")
    out = table.copy()
    for column in ("N", "shot", "amplitude"):
        values = pd.to_numeric(out[column], errors="coerce")
        if values.isna().any() or (values != np.round(values)).any():
            raise TraceFormatError(f"{where}: column {column} must hold integers")
        out[column] = values.astype(np.int64)
    n_values = out["N"].unique()
    if len(n_values) != 1 or n_values[0] < 2:
        raise TraceFormatError(f"{where}: column N must hold one chain size >= 2, got {n_values}")
    n_beads = int(n_values[0])
    problem = bead_number_problem(beads, n_beads)
    if problem:
        raise TraceFormatError(f"{where}: sensor columns (beads {beads}): {problem}")
    for column in ("v0_left_m_s", "v0_right_m_s", "t_s", *map(sensor_column, beads)):
        out[column] = pd.to_numeric(out[column], errors="coerce").astype(float)
    for column in ("t_s", *map(sensor_column, beads)):
        bad = ~np.isfinite(out[column].to_numpy())
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise TraceFormatError(
                f"{where}: column {column} has a missing or non-finite value at data row {row + 1}"
            )
    for shot, group in out.groupby("shot", sort=False):
        for column in ("source", "model", "kind", "amplitude"):
            if group[column].nunique() != 1:
                raise TraceFormatError(f"{where}: shot {shot} has several values of {column}")
        time = group["t_s"].to_numpy()
        if len(time) < 3:
            raise TraceFormatError(f"{where}: shot {shot} has fewer than 3 samples")
        step = np.diff(time)
        if np.any(step <= 0):
            raise TraceFormatError(f"{where}: shot {shot}: time is not strictly increasing")
        median = np.median(step)
        if np.any(np.abs(step - median) > TIME_STEP_TOLERANCE * median):
            raise TraceFormatError(f"{where}: shot {shot}: time is not evenly sampled")
    return out


def write_traces(table: pd.DataFrame, path: str | os.PathLike) -> None:
    """Validate ``table`` and write it as CSV, atomically (temporary file, then rename).

    Parameters
    ----------
    table : DataFrame
        A trace table.
    path : path
        Output CSV path; parent folders are created.
    """
    table = validate_traces(table, where=str(path))
    write_csv_atomic(table, path)


def read_traces(path: str | os.PathLike, *, check: bool = True) -> pd.DataFrame:
    """Read a trace CSV written by :func:`write_traces`, validated by default.

    Parameters
    ----------
    path : path
        CSV file.
    check : bool
        False for a file :func:`write_traces` wrote (a workflow job's input, checked by
        the job that wrote it): the columns are parsed with the format's dtypes and not
        checked again (a third of a second per file), giving the table
        :func:`validate_traces` would return.
    """
    path = Path(path)
    try:
        table = pd.read_csv(path, dtype=None if check else _format_dtypes(path))
    except FileNotFoundError:
        raise TraceFormatError(f"{path}: no such trace file") from None
    except (pd.errors.EmptyDataError, pd.errors.ParserError) as error:
        raise TraceFormatError(f"{path}: not a readable CSV trace file ({error})") from None
    return validate_traces(table, where=str(path)) if check else table


def _format_dtypes(path: Path) -> dict[str, type]:
    """The dtype of each numeric column of a trace file, as :func:`validate_traces` makes
    them (read off the header line)."""
    with open(path, newline="") as stream:
        names = stream.readline().rstrip("\r\n").split(",")
    dtypes = {}
    for name in names:
        if name in ("N", "shot", "amplitude"):
            dtypes[name] = np.int64
        elif name in ("v0_left_m_s", "v0_right_m_s", "t_s") or _SENSOR_COLUMN.match(name):
            dtypes[name] = float
    return dtypes


def save_trace_sets(sets: Mapping[str, Sequence[pd.DataFrame]], path: str | os.PathLike) -> None:
    """Sets of trace tables (a set: one table per chain) in one ``.npz`` file, without
    pickles, atomically: each column an array (text as unicode), read back identical,
    dtypes and bits, by :func:`load_trace_sets`.

    Parameters
    ----------
    sets : mapping
        Set name -> its trace tables.
    path : path
        The ``.npz`` file.
    """
    arrays = {"sets": np.array(list(sets), dtype=str)}
    for i, tables in enumerate(sets.values()):
        for j, table in enumerate(tables):
            for column in table.columns:
                values = table[column].to_numpy()
                arrays[f"{i}:{j}:{column}"] = (
                    values.astype(str) if values.dtype == object else values
                )
    with atomic_output(path) as temporary, open(temporary, "wb") as stream:
        np.savez(stream, **arrays)


def load_trace_sets(path: str | os.PathLike) -> dict[str, list[pd.DataFrame]]:
    """The sets of trace tables :func:`save_trace_sets` wrote: set name -> its tables.

    Parameters
    ----------
    path : path
        The ``.npz`` file.
    """
    columns: dict[int, dict[int, dict]] = {}
    with np.load(path, allow_pickle=False) as saved:
        names = [str(name) for name in saved["sets"]]
        for key in saved.files[1:]:
            i, j, column = key.split(":", 2)
            values = saved[key]
            if values.dtype.kind == "U":  # text as the table held it: Python str objects
                values = np.array(values.tolist(), dtype=object)
            columns.setdefault(int(i), {}).setdefault(int(j), {})[column] = values
    return {name: [pd.DataFrame(columns[i][j]) for j in sorted(columns.get(i, {}))]
            for i, name in enumerate(names)}  # fmt: skip


def iter_shots(table: pd.DataFrame):
    """Yield (shot id, shot metadata dict, time array s, {bead: force array N}) per shot."""
    beads = sensor_beads(table)
    for shot, group in table.groupby("shot", sort=True):
        first = group.iloc[0]
        meta = {c: first[c] for c in META_COLUMNS if c != "t_s"}
        forces = {b: group[sensor_column(b)].to_numpy() for b in beads}
        yield int(shot), meta, group["t_s"].to_numpy(), forces
