"""The paper's acceptance protocol: keep a collision only if the two waves matched.

Sec. IV: "When the incident waves registered by the sensors had amplitude difference no
greater than 5 %, it is considered that solitary waves have crossed at the middle of the
chain ... Data for which this condition is not fulfilled are not retained."

:func:`select_shots` applies it to the rows of ``pulses.csv``
(:func:`chain.analysis.pulse_rows.pulse_table`): a collision shot is kept when the incident
amplitudes F_L (LSTW at S1) and F_R (RSTW at S2) satisfy

    mismatch = |F_L - F_R| / ((F_L + F_R) / 2) <= tolerance,

a reference shot when its pulses were fitted at every sensor. A shot whose pulse was
not detected, or whose fit failed, is a rejected row with the reason, not an error.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.analysis.rows import is_ok
from chain.errors import ParameterError
from chain.labels import SKIPPED_REASON
from chain.traces import SHOT_COLUMNS

#: The paper's amplitude-match tolerance (5 %).
DEFAULT_TOLERANCE = 0.05

#: Columns of the selection table, in order.
SELECTION_COLUMNS = (*SHOT_COLUMNS, "F_left_N", "F_right_N", "mismatch", "kept", "reason")

#: Columns naming a series: the shot key is these plus ``shot``.
GROUP = ["source", "model", "N"]
_KEY = [*GROUP, "shot"]
_PULSE_COLUMNS = (*SHOT_COLUMNS, "sensor", "role", "estimator", "F_m_N", "ok")


def amplitude_mismatch(force_left_N, force_right_N):
    """Relative difference of two amplitudes, |F_L - F_R| / mean (dimensionless).

    Parameters
    ----------
    force_left_N, force_right_N : float or array
        Incident amplitudes of the left- and right-launched waves, N.
    """
    left = np.asarray(force_left_N, dtype=float)
    right = np.asarray(force_right_N, dtype=float)
    return np.abs(left - right) / (0.5 * (left + right))


def select_shots(
    pulses: pd.DataFrame,
    tolerance: float = DEFAULT_TOLERANCE,
    *,
    estimator: str = "fit_full",
    shots: pd.DataFrame | None = None,
) -> pd.DataFrame:
    """Apply the paper's acceptance filter to every shot of a pulse table.

    Parameters
    ----------
    pulses : DataFrame
        Rows of ``pulses.csv`` (columns of :func:`chain.analysis.pulse_rows.pulse_table`; needed:
        source, model, N, shot, kind, amplitude, sensor, role, estimator, F_m_N, ok,
        and reason when present).
    tolerance : float
        Largest accepted amplitude mismatch, as a fraction (0.05 = 5 %).
    estimator : str
        Estimator whose amplitudes are compared (the paper's: ``fit_full``).
    shots : DataFrame, optional
        The shots that were recorded (any table with source, model, N, shot, kind,
        amplitude, e.g. the trace table): a shot without any row in ``pulses`` becomes
        a rejected row "no pulse detected".

    Returns
    -------
    DataFrame
        One row per shot, columns :data:`SELECTION_COLUMNS`: F_left_N (incident LSTW
        at S1; for a reference, its amplitude at S1), F_right_N (incident RSTW at S2;
        NaN for a reference), mismatch (fraction; NaN when not computed), kept (bool),
        reason (why kept or rejected, e.g. "amplitude mismatch 7.2% > 5%").
    """
    if isinstance(tolerance, bool) or not isinstance(tolerance, int | float):
        raise ParameterError(f"tolerance must be a number, got {tolerance!r}")
    if not (math.isfinite(tolerance) and tolerance >= 0):
        raise ParameterError(f"tolerance must be a fraction >= 0, got {tolerance!r}")
    missing = [c for c in _PULSE_COLUMNS if c not in pulses.columns]
    if missing:
        raise ParameterError(f"pulses: missing columns {missing}")
    table = pulses[pulses["estimator"] == estimator]
    if table.empty and not pulses.empty:
        known = sorted(pulses["estimator"].unique())
        raise ParameterError(f"pulses: no rows for estimator {estimator!r}; present: {known}")

    rows = []
    seen = set()
    pulses_of = _first_pulses(table)
    for key, group in table.groupby(_KEY, sort=False):
        seen.add(tuple(key))
        first = group.iloc[0]
        base = dict(zip(_KEY, key), kind=first["kind"], amplitude=int(first["amplitude"]))
        if first["kind"] == "collision":
            rows.append({**base, **_judge_collision(pulses_of[tuple(key)], tolerance)})
        else:
            rows.append({**base, **_judge_reference(pulses_of[tuple(key)])})
    if shots is not None:
        absent = shots.drop_duplicates(_KEY)
        for record in absent.itertuples(index=False):
            key = tuple(getattr(record, c) for c in _KEY)
            if key in seen:
                continue
            seen.add(key)
            rows.append(
                {
                    **dict(zip(_KEY, key)),
                    "kind": record.kind,
                    "amplitude": int(record.amplitude),
                    **_verdict("no pulse detected (no pulse rows for this shot)"),
                }
            )
    selection = pd.DataFrame(rows, columns=SELECTION_COLUMNS)
    selection["kept"] = is_ok(selection, "kept")
    return selection.sort_values(_KEY, kind="stable").reset_index(drop=True)


def _verdict(reason: str, left=math.nan, right=math.nan, mismatch=math.nan, kept=False) -> dict:
    return {
        "F_left_N": left,
        "F_right_N": right,
        "mismatch": mismatch,
        "kept": kept,
        "reason": reason,
    }


def _first_pulses(table: pd.DataFrame) -> dict[tuple, dict[tuple, dict]]:
    """Shot key (source, model, N, shot) -> (sensor, role) -> the first row of that
    pulse in ``table``, as a dict with its ``ok`` flag (:func:`is_ok`) under ``_ok``.

    Built once, so that judging a shot looks its pulses up instead of filtering the table.
    """
    firsts = table.assign(_ok=is_ok(table)).drop_duplicates([*_KEY, "sensor", "role"])
    pulses: dict[tuple, dict[tuple, dict]] = {}
    for record in firsts.to_dict("records"):
        shot = pulses.setdefault(tuple(record[c] for c in _KEY), {})
        shot[(record["sensor"], record["role"])] = record
    return pulses


def _pulse(pulses: dict[tuple, dict], sensor: str, role: str):
    """The amplitude of one pulse of a shot (:func:`_first_pulses`), or (None, why it
    is missing)."""
    row = pulses.get((sensor, role))
    label = f"{role} pulse at {sensor}"
    if row is None:
        return None, f"no pulse detected ({label}: no row)"
    if not row["_ok"]:
        reason = str(row["reason"]) if "reason" in row and isinstance(row["reason"], str) else ""
        return None, f"{reason or 'fit failed'} ({label})"
    force = float(row["F_m_N"])
    if not (math.isfinite(force) and force > 0):
        return None, f"no positive amplitude ({label}: F_m = {force!r} N)"
    return force, ""


def _judge_collision(pulses: dict[tuple, dict], tolerance: float) -> dict:
    left, why_left = _pulse(pulses, "S1", "incident")
    right, why_right = _pulse(pulses, "S2", "incident")
    if left is None or right is None:
        why = "; ".join(w for w in (why_left, why_right) if w)
        return _verdict(why, left if left else math.nan, right if right else math.nan)
    mismatch = float(amplitude_mismatch(left, right))
    # A hair of slack so that a mismatch equal to the tolerance is not lost to rounding.
    kept = mismatch <= tolerance * (1 + 1e-12)
    relation = "<=" if kept else ">"
    reason = f"amplitude mismatch {100 * mismatch:.1f}% {relation} {100 * tolerance:g}%"
    return _verdict(("kept: " if kept else "") + reason, left, right, mismatch, kept)


def _judge_reference(pulses: dict[tuple, dict]) -> dict:
    sensors = sorted({sensor for sensor, _ in pulses}) or ["S1"]
    forces = {}
    problems = []
    for sensor in sensors:
        force, why = _pulse(pulses, sensor, "reference")
        forces[sensor] = force
        if force is None:
            problems.append(why)
    left = forces.get("S1") or math.nan
    if problems:
        return _verdict("; ".join(problems), left)
    return _verdict("kept: reference pulse fitted at " + " and ".join(sensors), left, kept=True)


def apply_selection(table: pd.DataFrame, selection: pd.DataFrame | None) -> pd.DataFrame:
    """Drop the rows of collision shots whose ``kept`` is False in ``selection``.

    Shots are matched on ``shot`` and on whichever of ``source, model, N`` both tables
    have. Reference shots and shots absent from ``selection`` are kept.

    Parameters
    ----------
    table : DataFrame
        Rows with a ``shot`` column (and ``kind`` if it holds reference shots).
    selection : DataFrame or None
        ``chain.analysis.selection.select_shots`` output (``shot``, ``kept``, ...); None keeps all.
    """
    if selection is None:
        return table
    keys = [c for c in (*GROUP, "shot") if c in table.columns and c in selection.columns]
    dropped = selection.loc[~is_ok(selection, "kept"), keys].drop_duplicates()
    if dropped.empty:
        return table
    marker = table[keys].merge(dropped.assign(_drop=True), on=keys, how="left")["_drop"]
    drop = marker.fillna(False).to_numpy(dtype=bool)
    if "kind" in table.columns:
        # Not in place: to_numpy may return a read-only view (pandas copy-on-write).
        drop = drop & (table["kind"] == "collision").to_numpy()
    return table.loc[~drop]


def selection_counts(selection: pd.DataFrame | None) -> list[dict]:
    """Kept and rejected shots of the acceptance protocol per series, chain and kind:
    ``{"model", "N", "kind", "kept", "rejected"}`` sorted by model, N, kind.

    Parameters
    ----------
    selection : DataFrame or None
        ``experiment/selection.csv`` (:func:`chain.analysis.selection.select_shots`).
    """
    if selection is None or not len(selection):
        return []
    kept = is_ok(selection, "kept")
    rows = []
    for (model, n, kind), group in selection.groupby(["model", "N", "kind"], sort=True):
        k = int(kept.loc[group.index].sum())
        rows.append(
            {
                "model": str(model),
                "N": int(n),
                "kind": str(kind),
                "kept": k,
                "rejected": len(group) - k,
            }
        )
    return rows


def skipped_shots(selection: pd.DataFrame | None) -> list[dict]:
    """Shots left out before the analysis for a dead or saturated channel.

    Parameters
    ----------
    selection : DataFrame or None
        ``experiment/selection.csv``.

    Returns
    -------
    list of dict
        ``{"model", "N", "shot", "reason"}`` of each row whose reason starts with
        :data:`SKIPPED_REASON`, in table order; empty when there is none.
    """
    if selection is None or not len(selection) or "reason" not in selection.columns:
        return []
    reasons = selection["reason"].astype(str)
    rows = selection[reasons.str.startswith(SKIPPED_REASON)]
    return [
        {"model": str(r.model), "N": int(r.N), "shot": int(r.shot), "reason": str(r.reason)}
        for r in rows.itertuples(index=False)
    ]
