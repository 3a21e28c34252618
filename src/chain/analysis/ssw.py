"""Secondary solitary waves (SSW) at the sensors: the small waves born where the two
pulses crossed, read behind each crossed pulse, with their errors.

At the paper's sensors the SSW has barely, or not yet, separated from the crossed pulse
(``chain.analysis.ssw_track`` follows it contact by contact). Every measurable row gets
a value with an error bar; whether it is a separate wave is a second, stricter question:

1. **Template.** The reference pulse at the same distance from the launching end (the
   reference shot of the same amplitude at S2: for LSTW crossed at S2 that is the same
   sensor; for RSTW crossed at S1 the symmetric sensor placement makes S2 the same
   distance from its launching end) is turned into a solitary wave of the crossed
   pulse's size by the Hertz self-similarity -- force scale a, time scale a^(-1/6) --
   and aligned on the crossed pulse by least squares on its rising edge and top (from
   T - tau to its highest sample, which the trailing SSW does not reach), a and the
   time shift free. ``template_misfit_N`` is the largest misfit there (of the
   smoothed residual, as the SSW is read from it).
2. **The value** (method ``residual``): the largest (signal - template), smoothed, from
   the crossed pulse's **trailing minimum** (where a distinct bump follows it, rule 4)
   or else from one tau behind the crossed peak, to :data:`WINDOW_TAUS` tau behind the
   peak. The smoothing is quadratic Savitzky-Golay, tau/2 long (the SSW is about tau
   wide, the noise is not). Method ``peak``: the distinct bump's smoothed height (only
   where there is one).
3. **Its error.** Systematic ``ssw_sys_N``: the template misfit on the rising edge (the
   template is no better than that behind the peak either; for ``peak``: the crossed
   pulse's tail under the bump, the smoothed signal at the trailing minimum).
   Statistical ``ssw_stat_N``: :data:`NOISE_SIGMAS` standard deviations of the smoothed
   noise (a 3-sigma bound, as the value is a maximum over ~10 independent smoothed
   samples, not one reading). ``ssw_err_N``: both in quadrature. A value not above its
   error is an **upper limit** (``upper_limit``; drawn at value + error).
4. **Resolved** (``resolved``, the strict rule): a distinct bump -- a local maximum of
   the smoothed signal within the window, of prominence at least
   :data:`MIN_PEAK_FRACTION` of the crossed pulse and :data:`MIN_PEAK_SNR` sigma of the
   smoothed noise -- whose largest residual exceeds ``ssw_floor_N`` =
   :data:`RESOLVE_FACTOR` x (template misfit + :data:`NOISE_SIGMAS` sigma).

``ok`` means measurable (``reason`` says why not). :func:`ssw_fit_table` fits
SSW = slope x F_m through the origin on every measurable row, weighted by its error
(Fig. 5), with a statistical and a systematic error of the slope.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.analysis.peaks import find_peaks
from chain.analysis.pulses import estimate_baseline
from chain.analysis.rows import is_ok
from chain.analysis.selection import apply_selection
from chain.analysis.smoothing import smoother
from chain.analysis.ssw_fits import (  # noqa: F401 (public names of this module too)
    RESOLUTION_COLUMNS,
    SSW_FIT_COLUMNS,
    proportional_slope,
    ssw_fit_table,
    ssw_parity_table,
    ssw_resolution_table,
)
from chain.traces import iter_shots, sensor_beads

#: The SSW is looked for from the crossed pulse's peak to this many tau after it.
WINDOW_TAUS = 6.0

#: A resolved SSW exceeds this many times (template misfit + noise), its floor.
RESOLVE_FACTOR = 2.0

#: The noise part of the floor, in standard deviations of the smoothed noise.
NOISE_SIGMAS = 3.0

#: Reason of the ``peak`` rows without a distinct bump to read.
NO_BUMP = "no distinct bump behind the crossed pulse"

#: Least prominence of a distinct SSW peak, as a fraction of the crossed pulse.
MIN_PEAK_FRACTION = 0.005

#: Least prominence of a distinct SSW peak in standard deviations of the smoothed noise.
MIN_PEAK_SNR = 8.0

SSW_METHODS = ("residual", "peak")

#: Columns of :func:`ssw_table` (after ``reason``: extras).
SSW_COLUMNS = tuple(
    "source model N shot amplitude sensor bead wave F_m_N ssw_N ssw_time_us method ok "
    "reason ssw_lag_us F_crossed_N reference_shot template_scale template_misfit_N "
    "ssw_floor_N trailing_min_us ssw_candidate_N ssw_sys_N ssw_stat_N ssw_err_N resolved "
    "upper_limit".split()
)


#: Crossed wave read at each sensor, and where its incident amplitude was measured.
_CROSSED = {"S2": ("LSTW", "S1"), "S1": ("RSTW", "S2")}


def _template(spline, time, scale, arrival, ref_arrival):
    # Zero outside the reference record, where the spline gives NaN. The alignment calls
    # this thousands of times: one pass, not np.nan_to_num's three (no +-inf here).
    source = ref_arrival + (time - arrival) * scale ** (1.0 / 6.0)
    values = scale * spline(source)
    values[np.isnan(values)] = 0.0
    return values


def measure_ssw(
    time_s,
    force_N,
    crossed_peak_N: float,
    crossed_arrival_s: float,
    crossed_tau_s: float,
    reference_time_s,
    reference_force_N,
    reference_peak_N: float,
    reference_arrival_s: float,
    *,
    baseline_N: float = 0.0,
    reference_baseline_N: float = 0.0,
    noise_N: float = 0.0,
    reference_noise_N: float = 0.0,
) -> dict:
    """SSW behind one crossed pulse, by both methods, with what its errors need.

    Parameters
    ----------
    time_s, force_N : array
        The crossed signal, s and N.
    crossed_peak_N, crossed_arrival_s, crossed_tau_s : float
        Its fitted F_m (N), T (s), tau (s) (``fit_full``).
    reference_time_s, reference_force_N : array
        The reference signal at the same distance from the launching end, s and N.
    reference_peak_N, reference_arrival_s : float
        Its fitted F_m (N) and T (s).
    baseline_N, reference_baseline_N : float
        Baseline offsets of the two signals, N.
    noise_N, reference_noise_N : float
        Noise standard deviations of the crossed and the reference signal, N (both
        enter the residual; the reference's scaled by a).

    Returns
    -------
    dict
        ``{"residual": (ssw_N, time_s, reason), "peak": (...), "scale": a, "misfit": N,
        "stat": N, "pedestal": N, "floor": N, "resolved": bool, "trailing_min_s": s,
        "candidate": N}``; ``reason`` is "" when the value was read (NaN otherwise);
        ``misfit`` is the largest smoothed |signal - template| on the rising edge,
        ``stat`` :data:`NOISE_SIGMAS` sigma of the smoothed noise, ``pedestal`` the
        smoothed signal at the trailing minimum, ``floor`` the least resolved residual,
        ``candidate`` the residual maximum over the distinct bump, ``resolved`` whether
        it clears the floor, ``trailing_min_s`` the time of the crossed pulse's trailing
        minimum (NaN without a distinct bump).
    """
    # Imported here: most jobs that import this module (for its tables' names) never
    # measure, and scipy.interpolate takes a tenth of a second to import.
    from scipy.interpolate import CubicSpline

    time = np.asarray(time_s, dtype=float)
    signal = np.asarray(force_N, dtype=float) - baseline_N
    ref_signal = np.asarray(reference_force_N, dtype=float) - reference_baseline_N
    nan = (math.nan, math.nan, "crossed pulse not sampled")
    result = {"residual": nan, "peak": nan, "scale": math.nan, "misfit": math.nan}
    result.update(floor=math.nan, trailing_min_s=math.nan, candidate=math.nan)
    result.update(stat=math.nan, pedestal=math.nan, resolved=False)
    spline = CubicSpline(np.asarray(reference_time_s, dtype=float), ref_signal, extrapolate=False)
    aligned = _align_template(
        time,
        signal,
        crossed_arrival_s,
        crossed_tau_s,
        crossed_peak_N / reference_peak_N,
        spline,
        reference_arrival_s,
    )
    if aligned is None:
        return result
    scale, shift, edge, top = aligned
    template = _template(spline, time, scale, shift, reference_arrival_s)
    last = int(np.flatnonzero(time <= time[top] + WINDOW_TAUS * crossed_tau_s)[-1])
    # Everything below reads samples from the rising edge to the window's end only.
    smooth, noise_gain = smoother(time, crossed_tau_s, edge.start, last + 1)
    residual = smooth(signal - template)
    # Measured on the smoothed residual, as the SSW is: the noise enters once, below.
    misfit = float(np.max(np.abs(residual[edge])))
    stat = NOISE_SIGMAS * noise_gain * math.hypot(noise_N, scale * reference_noise_N)
    result.update(scale=scale, misfit=misfit, floor=RESOLVE_FACTOR * (misfit + stat), stat=stat)
    prominence = max(MIN_PEAK_FRACTION * crossed_peak_N, MIN_PEAK_SNR * noise_gain * noise_N)
    smoothed = smooth(signal)
    bump = _distinct_bump(smoothed, top, last, prominence)
    # Behind the trailing minimum where there is one, else from one tau behind the peak.
    start = bump[0] if bump else int(np.searchsorted(time, time[top] + crossed_tau_s))
    if start > last:
        result.update(residual=(math.nan, math.nan, "window past the record"), peak=nan)
        return result
    best = start + int(np.argmax(residual[start : last + 1]))
    result["residual"] = (float(residual[best]), float(time[best]), "")
    result["peak"] = (math.nan, math.nan, NO_BUMP)
    if bump is None:
        return result
    low, peak, far = bump
    candidate = low + int(np.argmax(residual[low : far + 1]))
    result.update(trailing_min_s=float(time[low]), candidate=float(residual[candidate]))
    result.update(resolved=bool(residual[candidate] > result["floor"]))
    result.update(peak=(float(smoothed[peak]), float(time[peak]), ""), pedestal=smoothed[low])
    return result


def _align_template(time, signal, arrival, tau, scale_guess, spline, ref_arrival):
    """Fit the template's scale a and arrival on the crossed pulse's rising edge and top.

    Returns (a, arrival s, the rising edge as a slice, index of the top sample), or None
    when the pulse has fewer than 6 samples within tau of its arrival.
    """
    from scipy.optimize import least_squares  # imported here: see measure_ssw

    near = np.flatnonzero(np.abs(time - arrival) < tau)
    if near.size < 6:
        return None
    top = int(near[np.argmax(signal[near])])
    edge = slice(int(near[0]), top + 1)

    def misfit(params):
        return _template(spline, time[edge], params[0], params[1], ref_arrival) - signal[edge]

    solution = least_squares(
        misfit, (scale_guess, arrival), x_scale=(0.01, 0.01 * tau), bounds=([0, -np.inf], np.inf)
    )
    scale, shift = solution.x
    return float(scale), float(shift), edge, top


def _distinct_bump(smoothed, top: int, last: int, prominence: float):
    """The first local maximum after the crossed peak ``top`` (up to index ``last``)
    with at least ``prominence``: (trailing minimum, maximum, far base) indices, or None.

    Prominence is measured within [top, last], so the crossed pulse itself bounds the
    bump on the near side and the trailing minimum is the lowest point between them.
    """
    region = smoothed[top : last + 1]
    peaks, properties = find_peaks(region, prominence=prominence)
    if not peaks.size:
        return None
    peak = int(peaks[0])
    low = int(np.argmin(region[: peak + 1]))
    return top + low, top + peak, top + int(properties["right_bases"][0])


def ssw_table(
    traces: pd.DataFrame,
    pulses: pd.DataFrame,
    selection: pd.DataFrame | None = None,
    *,
    estimator: str = "fit_full",
) -> pd.DataFrame:
    """SSW amplitude behind each crossed pulse (the rows of ``ssw.csv``).

    One row per collision shot, sensor and method (``residual``, ``peak``).

    Parameters
    ----------
    traces : DataFrame
        The trace table the pulses came from (:mod:`chain.traces`).
    pulses : DataFrame
        ``pulses.csv`` rows of these traces (:func:`chain.analysis.pulse_rows.pulse_table`).
    selection : DataFrame, optional
        Shot selection (``shot``, ``kept``); collision shots with ``kept`` False are
        dropped. None keeps every shot.
    estimator : str
        Pulse estimator whose F_m, T, tau are used.

    Returns
    -------
    DataFrame
        Columns :data:`SSW_COLUMNS`. ``F_m_N`` is the incident amplitude of the crossed
        wave (at the first sensor it met), ``ssw_time_us`` the time of the SSW maximum
        (same origin as ``t_s``), ``ssw_lag_us`` its delay after the crossed pulse's T,
        ``template_scale`` the force ratio a of the template to the reference,
        ``template_misfit_N`` the largest smoothed |signal - template| on the rising edge,
        ``ssw_floor_N`` the least resolved value, ``ssw_candidate_N`` the residual
        maximum over the distinct bump whether or not it clears the floor (NaN
        without one), ``trailing_min_us`` the time of the crossed pulse's trailing
        minimum; ``ssw_sys_N``, ``ssw_stat_N``, ``ssw_err_N`` the systematic,
        statistical and total error (N), ``resolved`` the strict rule, ``upper_limit``
        value <= total error. Rows that cannot be measured: ``ok`` False, ``reason``
        why, ``ssw_N`` NaN.
    """
    pulses = _pulses_of_series(traces, pulses[pulses["estimator"] == estimator])
    pulses = apply_selection(pulses, selection)
    beads = sensor_beads(traces)
    context = {
        "bead_of": {"S1": beads[0], "S2": beads[-1]},
        "signals": {shot: (meta, t, forces) for shot, meta, t, forces in iter_shots(traces)},
        "lookup": {
            (row.source, row.model, row.N, row.shot, row.sensor, row.role): row
            for row in pulses.itertuples(index=False)
        },
        # The references of each (source, model, N, amplitude), in table order, found
        # once: their F_m (N) and their rows.
        "references_of": {
            key: (group["F_m_N"].to_numpy(float), list(group.itertuples(index=False)))
            for key, group in _usable_references(pulses).groupby(
                _REFERENCE_KEY, sort=False, dropna=False
            )
        },
        # (shot, bead) -> baseline and noise, N: a reference serves many collision shots.
        "baselines": {},
    }
    keys = ["source", "model", "N", "shot", "amplitude"]
    collisions = pulses[pulses["kind"] == "collision"][keys].drop_duplicates()
    rows = []
    for shot in collisions.itertuples(index=False):
        signal = context["signals"].get(shot.shot)
        if signal is None or (signal[0]["source"], signal[0]["model"], signal[0]["N"]) != (
            shot.source,
            shot.model,
            shot.N,
        ):
            continue
        for sensor in _CROSSED:
            rows.extend(_sensor_rows(shot, sensor, context))
    return pd.DataFrame(rows, columns=SSW_COLUMNS)


#: Columns a reference shares with the collision shots it serves as a template for.
_REFERENCE_KEY = ["source", "model", "N", "amplitude"]
#: Columns that name a series; one trace file holds one or a few.
_SERIES_KEY = ["source", "model", "N"]


def _pulses_of_series(traces: pd.DataFrame, pulses: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``pulses`` of the series in ``traces``: each trace file is measured
    against the pulses of every file, and the rest would only be looked up in vain."""
    wanted = set(traces[_SERIES_KEY].drop_duplicates().itertuples(index=False, name=None))
    keys = pulses[_SERIES_KEY].itertuples(index=False, name=None)
    return pulses[np.fromiter((key in wanted for key in keys), bool, len(pulses))]


def _usable_references(pulses: pd.DataFrame) -> pd.DataFrame:
    references = pulses[(pulses["role"] == "reference") & (pulses["sensor"] == "S2")]
    return references[is_ok(references)]


def _sensor_rows(shot, sensor: str, context: dict) -> list[dict]:
    """The two rows (one per method) of one collision shot at one sensor."""
    wave, first = _CROSSED[sensor]
    where = (shot.source, shot.model, shot.N, shot.shot)
    crossed = context["lookup"].get((*where, sensor, "crossed"))
    incident = context["lookup"].get((*where, first, "incident"))
    base = {**shot._asdict(), "sensor": sensor, "bead": context["bead_of"][sensor], "wave": wave}
    same = context["references_of"].get(tuple(getattr(shot, key) for key in _REFERENCE_KEY))
    reason = ""
    if crossed is None or not bool(crossed.ok):
        reason = "crossed pulse not measured"
    elif incident is None or not bool(incident.ok):
        reason = "incident pulse not measured"
    elif same is None:
        reason = "no usable reference shot of this amplitude"
    if reason:
        return [_row(base, method, math.nan, math.nan, math.nan, reason) for method in SSW_METHODS]
    # The reference closest in size to the crossed pulse needs the least rescaling (the
    # first of equals, NaN skipped, as pandas' idxmin).
    forces_N, references = same
    reference = references[int(np.nanargmin(np.abs(forces_N - crossed.F_m_N)))]
    result = _measure_at_sensor(shot.shot, sensor, crossed, reference, context)
    rows = []
    for method in SSW_METHODS:
        value, when, why = result[method]
        row = _row(base, method, incident.F_m_N, value, when, why)
        row.update(
            {
                "ssw_lag_us": (when - crossed.T_s) * 1e6,
                "F_crossed_N": crossed.F_m_N,
                "reference_shot": int(reference.shot),
                "template_scale": result["scale"],
                "template_misfit_N": result["misfit"],
                "ssw_floor_N": result["floor"],
                "trailing_min_us": result["trailing_min_s"] * 1e6,
                "ssw_candidate_N": result["candidate"],
                "resolved": bool(result["resolved"]),
            }
        )
        row.update(_errors(row["ssw_N"], result, method))
        rows.append(row)
    return rows


def _errors(value: float, result: dict, method: str) -> dict:
    """Systematic, statistical and total error (N) of one value, and the upper-limit flag."""
    systematic = result["misfit"] if method == "residual" else result["pedestal"]
    if not np.isfinite(value):
        systematic = math.nan
    total = math.hypot(systematic, result["stat"])
    return {
        "ssw_sys_N": systematic,
        "ssw_stat_N": result["stat"] if np.isfinite(value) else math.nan,
        "ssw_err_N": total,
        "upper_limit": bool(np.isfinite(value) and is_upper_limit(value, total)),
    }


def is_upper_limit(value_N: float, error_N: float) -> bool:
    """A value not above its (total) error is an upper limit, drawn at value + error.

    Parameters
    ----------
    value_N, error_N : float
        The SSW value and its total error, N.
    """
    return bool(value_N <= error_N)


def _measure_at_sensor(shot: int, sensor: str, crossed, reference, context: dict) -> dict:
    """:func:`measure_ssw` on the crossed signal at ``sensor`` against the reference
    shot's signal at S2 (the same distance from the launching end)."""
    bead, ref_bead = context["bead_of"][sensor], context["bead_of"]["S2"]
    _, time, forces = context["signals"][shot]
    _, ref_time, ref_forces = context["signals"][int(reference.shot)]
    baseline, noise = _baseline(context, shot, bead)
    ref_baseline, ref_noise = _baseline(context, int(reference.shot), ref_bead)
    return measure_ssw(
        time,
        forces[bead],
        crossed.F_m_N,
        crossed.T_s,
        crossed.tau_s,
        ref_time,
        ref_forces[ref_bead],
        reference.F_m_N,
        reference.T_s,
        baseline_N=baseline,
        reference_baseline_N=ref_baseline,
        noise_N=noise,
        reference_noise_N=ref_noise,
    )


def _baseline(context: dict, shot: int, bead: int) -> tuple[float, float]:
    """Baseline and noise (N) of one signal (:func:`estimate_baseline`), found once."""
    key = (shot, bead)
    if key not in context["baselines"]:
        _, time, forces = context["signals"][shot]
        context["baselines"][key] = estimate_baseline(time, forces[bead])
    return context["baselines"][key]


def _row(base, method, f_m, value, when, reason) -> dict:
    ok = not reason and bool(np.isfinite(value))
    return {
        **base,
        "F_m_N": f_m,
        "ssw_N": value if ok else math.nan,
        "ssw_time_us": when * 1e6 if ok else math.nan,
        "method": method,
        "ok": ok,
        "reason": reason,
        "ssw_sys_N": math.nan,
        "ssw_stat_N": math.nan,
        "ssw_err_N": math.nan,
        "resolved": False,
        "upper_limit": False,
    }
