"""The SSW's speed and size where it has separated: per shot and wave, the speed fitted
over the contacts where the tracked SSW is separated against Eq. 5's for its own amplitude,
its far-field SSW / F_m, where it separates (``ssw_speed.csv``), and the even / odd ratio
of the long chains. Reads ``ssw_track.csv`` rows (:func:`chain.analysis.ssw_track.ssw_track_table`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pandas as pd

from chain.analysis.regression import ratio_with_error
from chain.analysis.ssw_track import MIN_SPEED_CONTACTS

#: Columns of :func:`ssw_speed_table` (after ``first_separated_contact``: extras).
SPEED_COLUMNS = tuple(
    "source model N wave speed_m_s eq5_speed_m_s ratio first_separated_contact "
    "distance_beads first_detached_contact force_N F_m_N n_contacts shot n_shots "
    "n_shots_separated ratio_min ratio_max ssw_over_Fm ssw_over_Fm_err".split()
)


def shot_speed(track: pd.DataFrame, eq5_speed: Callable, spacing_m: float) -> dict:
    """SSW speed and far-field size of one shot and wave from its ``ssw_track.csv`` rows.

    Parameters
    ----------
    track : DataFrame
        The rows of one (shot, wave).
    eq5_speed : callable
        Eq. 5: solitary-wave speed (m/s) from its peak contact force (N), e.g.
        ``lambda f: nesterenko_speed_from_force(f, material, radius)``.
    spacing_m : float
        Distance between neighbouring contacts (the bead diameter), m.

    Returns
    -------
    dict
        ``first_separated_contact`` (the first separated contact outward from the
        collision point, or None), ``distance_beads`` (its distance from it),
        ``first_detached_contact`` (or None), ``n_contacts`` (of the fit),
        ``speed_m_s``, ``eq5_speed_m_s``, ``force_N`` (mean SSW maximum over the fit),
        ``ratio`` (NaN below :data:`MIN_SPEED_CONTACTS` contacts), ``far_over_Fm`` (SSW /
        F_m at the last contact of its first separated run before the main pulse
        reaches the second-to-last contact: the farthest it is seen undisturbed; detached or not,
        as with Kuwabara-Kono the tail between the two waves rarely empties) and
        ``far_change`` (how much SSW / F_m changed over the last MIN_SPEED_CONTACTS
        contacts: not yet settled by that much).
    """
    result, run, undisturbed = _speed_run(track)
    result.update(far_over_Fm=math.nan, far_change=math.nan)
    if len(undisturbed) >= MIN_SPEED_CONTACTS:
        size = (undisturbed["force_N"] / undisturbed["F_m_N"]).to_numpy(float)
        result.update(far_over_Fm=size[-1], far_change=abs(size[-1] - size[-MIN_SPEED_CONTACTS]))
    if len(run) < MIN_SPEED_CONTACTS:
        return result
    slope_s = np.polyfit(run["distance_beads"], run["time_us"] * 1e-6, 1)[0]
    force = float(run["force_N"].mean())
    result.update(speed_m_s=spacing_m / slope_s, eq5_speed_m_s=float(eq5_speed(force)))
    result.update(force_N=force, ratio=result["speed_m_s"] / result["eq5_speed_m_s"])
    return result


def _speed_run(track: pd.DataFrame) -> tuple[dict, pd.DataFrame, pd.DataFrame]:
    """Where the SSW separates and detaches; the contacts its speed is fitted on (the
    detached ones of its first run of separated contacts, before the main pulse reaches
    the second-to-last contact); and that run's contacts before then, detached or not."""
    rows = track.sort_values("distance_beads")
    separated = rows["separated"].to_numpy(bool)
    result = {"first_separated_contact": None, "distance_beads": math.nan, "n_contacts": 0}
    result["first_detached_contact"] = None
    result.update(speed_m_s=math.nan, eq5_speed_m_s=math.nan, force_N=math.nan, ratio=math.nan)
    if not separated.any():
        return result, rows.iloc[:0], rows.iloc[:0]
    first = int(np.argmax(separated))
    stop = first + int(np.argmin(np.append(separated[first:], False)))
    run = rows.iloc[first:stop]
    result["first_separated_contact"] = int(rows["contact"].iloc[first])
    result["distance_beads"] = float(rows["distance_beads"].iloc[first])
    detached = run[run["detached"].to_numpy(bool)]
    if not detached.empty:
        result["first_detached_contact"] = int(detached["contact"].iloc[0])
    # The chain ahead unloads once the main pulse has reached the end; the last
    # contact's own peak comes late (the end bead flies off), so the one before it.
    end = rows["main_time_us"].iloc[-2] if len(rows) > 1 else rows["main_time_us"].iloc[-1]
    result["n_contacts"] = int((detached["time_us"] < end).sum())
    return result, detached[detached["time_us"] < end], run[run["time_us"] < end]


def ssw_speed_table(track: pd.DataFrame, eq5_speed: Callable, spacing_m: float) -> pd.DataFrame:
    """The rows of ``ssw_speed.csv``: is the SSW a solitary wave?

    Per shot and wave, the SSW's speed from its arrival times on its first run of
    separated contacts (:func:`shot_speed`), against Eq. 5's speed for its own mean
    amplitude. One row per (source, model, N, wave): the shot with the median ratio
    (lower median), with ``ratio_min``/``ratio_max`` over the shots that have a speed,
    ``n_shots`` and ``n_shots_separated`` (shots with any separated contact).

    Parameters
    ----------
    track : DataFrame
        ``ssw_track.csv`` rows (:func:`ssw_track_table`).
    eq5_speed : callable
        Eq. 5, peak force (N) -> speed (m/s).
    spacing_m : float
        Contact spacing (bead diameter), m.

    Returns
    -------
    DataFrame
        Columns :data:`SPEED_COLUMNS`; speeds in m/s, ``ratio`` = speed / Eq. 5;
        ``ssw_over_Fm`` and its error: the SSW far from the collision point
        (:func:`shot_speed`'s ``far_over_Fm``, mean over the shots with a speed).
    """
    rows = []
    for key, group in track.groupby(["source", "model", "N", "wave"], sort=True):
        shots = [
            {"shot": int(shot), "F_m_N": float(rows_["F_m_N"].iloc[0])}
            | shot_speed(rows_, eq5_speed, spacing_m)
            for shot, rows_ in group.groupby("shot", sort=True)
        ]
        rows.append(_speed_row(dict(zip(["source", "model", "N", "wave"], key)), shots))
    table = pd.DataFrame(rows, columns=SPEED_COLUMNS)
    for column in ("first_separated_contact", "first_detached_contact"):
        table[column] = table[column].astype("Int64")
    return table


def _speed_row(base: dict, shots: list[dict]) -> dict:
    with_speed = sorted((s for s in shots if np.isfinite(s["ratio"])), key=lambda s: s["ratio"])
    separated = [s for s in shots if s["first_separated_contact"] is not None]
    if with_speed:
        chosen = with_speed[(len(with_speed) - 1) // 2]
    elif separated:
        chosen = min(separated, key=lambda s: s["distance_beads"])
    else:
        chosen = shots[0]
    ratios = [s["ratio"] for s in with_speed]
    return base | {
        **{name: chosen[name] for name in SPEED_COLUMNS if name in chosen},
        "n_shots": len(shots),
        "n_shots_separated": len(separated),
        "ratio_min": min(ratios, default=math.nan),
        "ratio_max": max(ratios, default=math.nan),
        **_far_field([s for s in shots if np.isfinite(s["far_over_Fm"])]),
    }


def _far_field(shots: list[dict]) -> dict:
    """SSW / F_m far from the collision point over the shots that have it: the mean, and
    its error, the shot-to-shot spread and the mean change over the last contacts
    (how far from settled) in quadrature."""
    far = np.array([s["far_over_Fm"] for s in shots], dtype=float)
    if not far.size:
        return {"ssw_over_Fm": math.nan, "ssw_over_Fm_err": math.nan}
    spread = float(np.std(far, ddof=1)) if far.size > 1 else 0.0
    change = float(np.mean([s["far_change"] for s in shots]))
    return {"ssw_over_Fm": float(np.mean(far)), "ssw_over_Fm_err": math.hypot(spread, change)}


#: Columns of :func:`separation_table` (summary key ``ssw_separation``).
SEPARATION_COLUMNS = tuple(
    "model N wave first_separated_contact distance_beads speed_ratio n_shots_separated "
    "n_shots".split()
)


def separation_table(speed: pd.DataFrame) -> pd.DataFrame:
    """Where the SSW separates from the crossed pulse, per model, chain and wave.

    Parameters
    ----------
    speed : DataFrame
        ``ssw_speed.csv`` rows (:func:`ssw_speed_table`).

    Returns
    -------
    DataFrame
        Columns :data:`SEPARATION_COLUMNS`: the first separated contact (NA if never),
        its distance from the collision point in beads, and the SSW's speed over Eq. 5's
        (NaN where it never detaches over enough contacts to fit a speed), for the
        shot of :func:`ssw_speed_table`; ``n_shots_separated`` of ``n_shots`` shots
        separate at all.
    """
    table = speed.rename(columns={"ratio": "speed_ratio"})
    return table[list(SEPARATION_COLUMNS)].reset_index(drop=True)


#: Columns of :func:`far_field_parity` (summary key ``ssw_far_field``).
FAR_FIELD_COLUMNS = tuple(
    "source model even_N odd_N even even_err odd odd_err ratio ratio_err".split()
)


def far_field_parity(speed: pd.DataFrame) -> pd.DataFrame:
    """The SSW far from the collision point, even chain over odd, per source and model.

    The longest even and the longest odd chain with a far-field value (LSTW; RSTW is its
    mirror) are compared: SSW / F_m of each with its error, and their ratio with its
    error (relative errors in quadrature).

    Parameters
    ----------
    speed : DataFrame
        ``ssw_speed.csv`` rows (:func:`ssw_speed_table`).

    Returns
    -------
    DataFrame
        Columns :data:`FAR_FIELD_COLUMNS` (SSW / F_m dimensionless); no row for a model
        without both an even and an odd chain.
    """
    rows = []
    usable = speed[(speed["wave"] == "LSTW") & np.isfinite(speed["ssw_over_Fm"])]
    for (source, model), group in usable.groupby(["source", "model"], sort=True):
        even = group[group["N"] % 2 == 0].sort_values("N")
        odd = group[group["N"] % 2 == 1].sort_values("N")
        if even.empty or odd.empty:
            continue
        e, o = even.iloc[-1], odd.iloc[-1]
        rows.append(
            {"source": source, "model": model, "even_N": int(e["N"]), "odd_N": int(o["N"])}
            | {"even": e["ssw_over_Fm"], "even_err": e["ssw_over_Fm_err"]}
            | {"odd": o["ssw_over_Fm"], "odd_err": o["ssw_over_Fm_err"]}
            | ratio_with_error(
                e["ssw_over_Fm"], e["ssw_over_Fm_err"], o["ssw_over_Fm"], o["ssw_over_Fm_err"]
            )
        )
    return pd.DataFrame(rows, columns=FAR_FIELD_COLUMNS)
