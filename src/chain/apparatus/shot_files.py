"""Shot files of a measured dataset (one CSV per shot): read with every problem listed,
write, and tell dead or saturated channels.

A shot file is ``t_s,bead<n>_V,...`` then one sample per line (``data/README.md``).
:func:`shot_file_problems` reads one and returns its samples or the list of everything
wrong with it, one line per problem naming the file, the line as an editor numbers it
(header = line 1) and the column; :func:`read_shot_csv` raises them as
:class:`MeasuredDataError`. :func:`channel_faults` names channels that carry no signal
(flat) or that hit the digitiser's limit: data that parse but cannot be trusted.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from chain.apparatus.acquisition import adc_step
from chain.apparatus.measured_format import (
    MAX_PROBLEMS,
    TIME_COLUMN,
    TIME_STEP_TOLERANCE,
    MeasuredDataError,
    problem_list,
    voltage_column,
)
from chain.atomic import write_text_atomic

#: A channel with at most this many distinct values is dead (flat, or one ADC code of
#: flicker): a sensor that saw a pulse crosses many codes.
DEAD_DISTINCT_VALUES = 2

#: Without ``adc_bits``, readings within this fraction of ``adc_range_V`` are at the limit.
SATURATION_MARGIN = 0.01


def _header_problems(where: str, header: list[str], expected: list[str]) -> list[str]:
    wanted = f"(expected header {','.join(expected)}: time in s, sensors in V, S1 first)"
    missing = [name for name in expected if name not in header]
    extra = [name for name in header if name not in expected]
    problems = []
    if missing:
        problems.append(f"{where} line 1: missing columns {missing} {wanted}")
    if extra:
        problems.append(f"{where} line 1: unexpected columns {extra} {wanted}")
    if not problems and header != expected:
        problems.append(
            f"{where} line 1: columns must be in the order {','.join(expected)}, got "
            f"{','.join(header)}"
        )
    return problems


def _cell_problems(where: str, rows: list[list[str]], columns: list[str], limit: int):
    """One problem per empty, non-numeric or non-finite cell (slow path, errors only)."""
    problems = []
    for number, row in enumerate(rows, start=2):
        for column, field in zip(columns, row):
            text = field.strip()
            try:
                value = float(text) if text else None
            except ValueError:
                problems.append(f"{where} line {number}: column {column}: {text!r} is not a number")
                continue
            if value is None:
                problems.append(
                    f"{where} line {number}: column {column}: missing value (empty field)"
                )
            elif not math.isfinite(value):
                problems.append(
                    f"{where} line {number}: column {column}: missing or non-finite value {text!r}"
                )
            if len(problems) > limit:  # one more than listed: the caller says "and more"
                return problems
    return problems


def _time_problems(where, time, body, interval, limit) -> list[str]:
    """Time must increase, in steps of ``interval`` (or of the median step) within 1 %."""
    step = np.diff(time)
    problems = []
    # Step i joins data rows i and i + 1, i.e. lines i + 2 and i + 3.
    for i in np.flatnonzero(step <= 0)[: limit + 1]:
        problems.append(
            f"{where} line {i + 3}: column {TIME_COLUMN}: time {body[i + 1].split(',')[0].strip()} "
            f"s does not increase (previous sample {body[i].split(',')[0].strip()} s)"
        )
    nominal = float(np.median(step)) if interval is None else interval
    what = "sampling_interval_s" if interval is not None else "the median step"
    uneven = np.flatnonzero((step > 0) & (np.abs(step - nominal) > TIME_STEP_TOLERANCE * nominal))
    if uneven.size > step.size // 2:
        # A wrong interval or unit, not a glitch: one line says it better than hundreds.
        typical = float(np.median(step[uneven]))
        problems.append(
            f"{where} line {uneven[0] + 3}: column {TIME_COLUMN}: {uneven.size} of {step.size} "
            f"time steps ({typical:.6g} s typically) differ from {what} {nominal:.6g} s "
            "(time not in seconds, or the wrong sampling_interval_s)"
        )
        return problems[:limit]
    for i in uneven[: max(limit + 1 - len(problems), 0)]:
        problems.append(
            f"{where} line {i + 3}: column {TIME_COLUMN}: time step {step[i]:.6g} s differs from "
            f"{what} {nominal:.6g} s (uneven sampling, or time not in seconds)"
        )
    return problems


def _count_problems(where, rows: int, samples: int | None) -> list[str]:
    if samples is not None and rows != samples:
        hint = " (truncated file?)" if rows < samples else ""
        return [f"{where}: {rows} data rows, metadata samples: {samples}{hint}"]
    if rows < 3:
        return [f"{where}: {rows} data rows, need at least 3 (truncated file?)"]
    return []


def _body_lines(where: str, text: str) -> tuple[list[str] | None, list[str]]:
    lines = text.splitlines()
    # Blank lines at the end are harmless (editors add them); elsewhere they are errors.
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        return None, [f"{where}: empty file (expected a header line {TIME_COLUMN},... and samples)"]
    return lines, []


def shot_file_problems(
    path: str | os.PathLike,
    sensor_beads: Sequence[int],
    sampling_interval_s: float | None = None,
    samples: int | None = None,
    limit: int = MAX_PROBLEMS,
) -> tuple[np.ndarray | None, list[str]]:
    """Read one shot file and list everything wrong with it: (its samples, (S, 1 +
    n_sensors), time s then volts V per row, or None when there are problems; the
    problems, one line each: file, line, column, what was expected).

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
    samples : int, optional
        Expected number of samples (data rows); without it, at least 3.
    limit : int
        Stop listing after this many problems (plus one, so that callers know more
        were found).
    """
    where = Path(path)
    try:
        text = where.read_bytes().decode("utf-8-sig")
    except FileNotFoundError:
        return None, [f"{where}: no such file"]
    except UnicodeDecodeError as error:
        return None, [f"{where}: not a text CSV file ({error})"]
    lines, problems = _body_lines(where, text)
    if problems:
        return None, problems
    expected = [TIME_COLUMN] + [voltage_column(b) for b in sensor_beads]
    problems = _header_problems(where, [name.strip() for name in lines[0].split(",")], expected)
    if problems:
        return None, problems
    body = lines[1:]
    problems = _count_problems(where, len(body), samples)
    rows = [line.split(",") for line in body]
    width = len(expected)
    for number, row in enumerate(rows, start=2):
        if len(row) != width:
            hint = " (truncated file?)" if number == len(rows) + 1 else ""
            problems.append(f"{where} line {number}: {len(row)} fields, expected {width}{hint}")
    if len(body) < 3 or len(problems) > len(_count_problems(where, len(body), samples)):
        return None, problems[: limit + 1]
    try:
        data = np.array(rows, dtype=float)
    except ValueError:
        data = None
    if data is None or not np.all(np.isfinite(data)):
        cells = _cell_problems(where, rows, expected, limit)
        if cells or data is None:
            return None, (problems + cells)[: limit + 1]
    problems += _time_problems(where, data[:, 0], body, sampling_interval_s, limit)
    return (None if problems else data), problems[: limit + 1]


def read_shot_csv(
    path: str | os.PathLike,
    sensor_beads: Sequence[int],
    sampling_interval_s: float | None = None,
    samples: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Read and check one shot file (rules: :func:`shot_file_problems`): (time (S,) s,
    volts (n_sensors, S) V), or :class:`MeasuredDataError` listing every problem."""
    data, problems = shot_file_problems(path, sensor_beads, sampling_interval_s, samples)
    if problems:
        raise MeasuredDataError(problem_list(problems))
    return data[:, 0], data[:, 1:].T.copy()


def saturation_limits(
    adc_range_V: float | None, adc_bits: int | None = None
) -> tuple[float, float] | None:
    """Readings (V) beyond which a digitiser is at its limit: (low, high), None if unknown.

    A ``bits``-bit ADC spanning [-range, +range) reads -range .. range - 1 code: its
    extreme codes are at the limit. Without the bits, readings within
    :data:`SATURATION_MARGIN` of the range count as at it.

    Parameters
    ----------
    adc_range_V : float or None
        Half span, V (metadata ``adc_range_V``).
    adc_bits : int, optional
        Resolution, bits (metadata ``adc_bits``).
    """
    if adc_range_V is None:
        return None
    if adc_bits is not None:
        step = adc_step(adc_bits, adc_range_V)
        return -adc_range_V + 0.5 * step, adc_range_V - 1.5 * step
    margin = SATURATION_MARGIN * adc_range_V
    return -adc_range_V + margin, adc_range_V - margin


def channel_faults(
    where: str,
    volts: np.ndarray,
    sensor_beads: Sequence[int],
    limits_V: tuple[float, float] | None = None,
) -> list[str]:
    """Dead or saturated channels of one shot, one line each (empty when all is well).

    Parameters
    ----------
    where : str
        File name used in messages.
    volts : (n_sensors, S) array
        Sensor voltages, V, S1 first.
    sensor_beads : sequence of int
        Bead of each sensor.
    limits_V : (low, high), optional
        :func:`saturation_limits`: a reading outside low..high is at the ADC limit.
        None: saturation is not checked (the metadata gives no ``adc_range_V``).
    """
    faults = []
    for bead, channel in zip(sensor_beads, volts):
        column = voltage_column(bead)
        distinct = np.unique(channel)
        if distinct.size <= DEAD_DISTINCT_VALUES:
            values = ", ".join(f"{v:g}" for v in distinct)
            faults.append(
                f"{where}: column {column}: dead channel (flat: only {values} V in "
                f"{channel.size} samples; expected a pulse)"
            )
        elif limits_V is not None:
            low, high = limits_V
            at = np.flatnonzero((channel < low) | (channel > high))
            if at.size:
                faults.append(
                    f"{where} line {at[0] + 2}: column {column}: saturated channel ({at.size} "
                    f"samples at the ADC limit, outside {low:.6g}..{high:.6g} V)"
                )
    return faults


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
    header = ",".join([TIME_COLUMN] + [voltage_column(b) for b in sensor_beads])
    # The text of np.savetxt(fmt=row format, delimiter=",", header=header, comments=""),
    # formatted in one operation instead of one per row.
    row = ",".join(["%.10g"] + ["%.7g"] * len(sensor_beads)) + "\n"
    values = np.column_stack([time, volts.T]).ravel().tolist()
    write_text_atomic(header + "\n" + (row * time.size) % tuple(values), Path(path))
