"""The rows of ``pulses.csv``: every main pulse of every shot of a trace table.

Each sensor signal of each shot is split into its main pulses
(:func:`chain.analysis.pulses.find_pulses`) and every pulse is measured with each asked
estimator (:func:`chain.analysis.pulses.measure_pulse`). Sensor S1 is the first sensor
column of the trace table, S2 the last. Roles (see ``docs/interfaces.md``): in a
collision shot the 1st pulse at S1 is the incident LSTW and the 2nd the crossed RSTW; at
S2 the 1st is the incident RSTW and the 2nd the crossed LSTW; a reference shot has one
pulse per sensor, role ``reference``, wave LSTW.
"""

from __future__ import annotations

import pandas as pd

from chain.analysis.pulses import (
    ESTIMATORS,
    PulseFit,
    estimate_baseline,
    find_pulses,
    measure_pulse,
)
from chain.errors import ParameterError
from chain.traces import SHOT_COLUMNS, iter_shots, sensor_beads

#: Columns of :func:`pulse_table`, in order.
PULSE_COLUMNS = SHOT_COLUMNS + tuple(
    "sensor bead role wave estimator F_m_N T_s tau_s F_m_stderr_N T_stderr_s tau_stderr_s "
    "ok reason baseline_N noise_N n_samples".split()
)


def pulse_table(traces: pd.DataFrame, estimators=("fit_full",)) -> pd.DataFrame:
    """The rows of ``pulses.csv`` (:data:`PULSE_COLUMNS`): every main pulse of every
    shot, per estimator.

    Roles as in the module docstring; pulses found with
    :func:`chain.analysis.pulses.find_pulses`' default thresholds. A pulse that is not
    detected gives rows with ``ok`` False and reason "no pulse detected"; when a
    collision signal shows one pulse only, it is taken as the incident one.

    Parameters
    ----------
    traces : DataFrame
        A trace table (:mod:`chain.traces`).
    estimators : sequence of str
        Names from :data:`chain.analysis.pulses.ESTIMATORS`.
    """
    estimators = tuple(estimators)
    unknown = [e for e in estimators if e not in ESTIMATORS]
    if unknown:
        raise ParameterError(f"unknown estimators {unknown}; choose from {ESTIMATORS}")
    beads = sensor_beads(traces)
    sensors = [("S1", beads[0])] + ([("S2", beads[-1])] if len(beads) > 1 else [])
    rows = []
    for shot, meta, time, forces in iter_shots(traces):
        shot_columns = {
            "source": meta["source"],
            "model": meta["model"],
            "N": int(meta["N"]),
            "shot": shot,
            "kind": meta["kind"],
            "amplitude": int(meta["amplitude"]),
        }
        for sensor, bead in sensors:
            roles = _roles(meta["kind"], sensor)
            columns = {**shot_columns, "sensor": sensor, "bead": bead}
            rows += _sensor_rows(time, forces[bead], roles, estimators, columns)
    return pd.DataFrame(rows, columns=PULSE_COLUMNS)


def _sensor_rows(time, force, roles: list[tuple[str, str]], estimators, columns) -> list[dict]:
    """The rows of one sensor signal (``time`` s, ``force`` N) of one shot: each expected
    pulse (``roles``, in time order) measured with each estimator; ``columns`` are the
    shot and sensor ones."""
    baseline, noise = estimate_baseline(time, force)
    segments = find_pulses(time, force, max_pulses=len(roles), baseline_N=baseline, noise_N=noise)
    rows = []
    for i, (role, wave) in enumerate(roles):
        if i < len(segments):
            part = segments[i].slice
            fits = measure_pulse(
                time[part], force[part], estimators, baseline_N=baseline, noise_N=noise
            )
        else:
            found = f" ({len(segments)} of {len(roles)} found)" if segments else ""
            fits = dict.fromkeys(estimators, PulseFit.failed("no pulse detected" + found))
        for estimator in estimators:
            fit = fits[estimator]
            rows.append(
                {
                    **columns,
                    "role": role,
                    "wave": wave,
                    "estimator": estimator,
                    **_fit_columns(fit),
                    "baseline_N": baseline,
                    "noise_N": noise,
                }
            )
    return rows


def _roles(kind: str, sensor: str) -> list[tuple[str, str]]:
    """(role, wave) of each pulse a sensor of a ``kind`` shot sees, in time order."""
    if kind == "reference":
        return [("reference", "LSTW")]
    if sensor == "S1":
        return [("incident", "LSTW"), ("crossed", "RSTW")]
    return [("incident", "RSTW"), ("crossed", "LSTW")]


def _fit_columns(fit: PulseFit) -> dict:
    """A :class:`~chain.analysis.pulses.PulseFit` as ``pulses.csv`` columns."""
    return {
        "F_m_N": fit.peak_force,
        "T_s": fit.arrival_time,
        "tau_s": fit.tau,
        "F_m_stderr_N": fit.peak_force_stderr,
        "T_stderr_s": fit.arrival_time_stderr,
        "tau_stderr_s": fit.tau_stderr,
        "ok": fit.ok,
        "reason": fit.reason,
        "n_samples": fit.n_samples,
    }
