"""Secondary solitary waves (SSW) at the sensors: the small waves born where the two
pulses crossed, read behind each crossed pulse.

At the paper's sensors the SSW has barely, or not yet, separated from the crossed pulse
(``chain.analysis.ssw_track`` follows it contact by contact). A value is therefore
reported only where the SSW is **resolved at the sensor**:

1. **Template.** The reference pulse at the same distance from the launching end (the
   reference shot of the same amplitude at S2: for LSTW crossed at S2 that is the same
   sensor; for RSTW crossed at S1 the symmetric sensor placement makes S2 the same
   distance from its launching end) is turned into a solitary wave of the crossed
   pulse's size by the Hertz self-similarity -- force scale a, time scale a^(-1/6) --
   and aligned on the crossed pulse by least squares on its rising edge and top (from
   T - tau to its highest sample, which the trailing SSW does not reach), a and the
   time shift free. ``template_misfit_N`` is the largest misfit there (of the
   smoothed residual, as the SSW is read from it).
2. **A distinct bump.** Within :data:`WINDOW_TAUS` tau behind the crossed peak, the
   (smoothed) signal must have a local maximum of prominence at least
   :data:`MIN_PEAK_FRACTION` of the crossed pulse and :data:`MIN_PEAK_SNR` sigma of the
   smoothed noise. The lowest point between the crossed peak and that maximum is the
   crossed pulse's **trailing minimum**; nothing before it is ever read as SSW.
3. **Its size.** ``residual``: the largest value of (signal - template), smoothed, from
   the trailing minimum to the bump's far base. ``peak``: the bump's height above the
   baseline. The smoothing is quadratic Savitzky-Golay, tau/2 long (the SSW is about
   tau wide, the noise is not).
4. **Above the floor.** The residual must exceed ``ssw_floor_N`` =
   :data:`RESOLVE_FACTOR` x (template misfit + :data:`NOISE_SIGMAS` sigma of the
   smoothed noise): residuals of the size of the misfit where no SSW can be are shape
   mismatch, not SSW.

Otherwise both rows have ``ok`` False with the reason :data:`NOT_RESOLVED`.
:func:`ssw_fit_table` fits SSW = slope x F_m through the origin on resolved rows (Fig. 5).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.analysis.pulses import estimate_baseline
from chain.analysis.regression import fit_proportional
from chain.analysis.rows import is_ok
from chain.analysis.selection import apply_selection
from chain.traces import iter_shots, sensor_beads

#: The SSW is looked for from the crossed pulse's peak to this many tau after it.
WINDOW_TAUS = 6.0

#: A resolved SSW exceeds this many times (template misfit + noise), its floor.
RESOLVE_FACTOR = 2.0

#: The noise part of the floor, in standard deviations of the smoothed noise.
NOISE_SIGMAS = 3.0

#: Reason of the rows where no SSW clears the floor.
NOT_RESOLVED = "not resolved at the sensor"

#: Least prominence of a distinct SSW peak, as a fraction of the crossed pulse.
MIN_PEAK_FRACTION = 0.005

#: Least prominence of a distinct SSW peak in standard deviations of the smoothed noise.
MIN_PEAK_SNR = 8.0

SSW_METHODS = ("residual", "peak")

#: Columns of :func:`ssw_table` (after ``reason``: extras).
SSW_COLUMNS = (
    "source",
    "model",
    "N",
    "shot",
    "amplitude",
    "sensor",
    "bead",
    "wave",
    "F_m_N",
    "ssw_N",
    "ssw_time_us",
    "method",
    "ok",
    "reason",
    "ssw_lag_us",
    "F_crossed_N",
    "reference_shot",
    "template_scale",
    "template_misfit_N",
    "ssw_floor_N",
    "trailing_min_us",
    "ssw_candidate_N",
)

#: Columns of :func:`ssw_fit_table`.
SSW_FIT_COLUMNS = ("source", "model", "N", "slope", "slope_stderr", "n_points", "method")

#: Crossed wave read at each sensor, and where its incident amplitude was measured.
_CROSSED = {"S2": ("LSTW", "S1"), "S1": ("RSTW", "S2")}


def rescaled_template(time_s, reference_time_s, reference_force_N, scale, arrival_s, ref_arrival_s):
    """A reference pulse turned into the solitary wave of ``scale`` times its force, N.

    Hertz self-similarity: a solitary wave ``scale`` times stronger is ``scale^(-1/6)``
    times shorter, F(t) = scale * F_ref(T_ref + (t - T) scale^(1/6)).

    Parameters
    ----------
    time_s : array
        Times at which to evaluate the template, s.
    reference_time_s, reference_force_N : array
        The reference signal (baseline removed), s and N.
    scale : float
        Force ratio a (template / reference).
    arrival_s : float
        Arrival time T of the template, s.
    ref_arrival_s : float
        Arrival time T_ref of the reference pulse, s.
    """
    from scipy.interpolate import CubicSpline  # imported here: see measure_ssw

    spline = CubicSpline(reference_time_s, reference_force_N, extrapolate=False)
    return _template(spline, np.asarray(time_s, dtype=float), scale, arrival_s, ref_arrival_s)


def _template(spline, time, scale, arrival, ref_arrival):
    # Zero outside the reference record (the spline does not extrapolate).
    source = ref_arrival + (time - arrival) * scale ** (1.0 / 6.0)
    return np.nan_to_num(scale * spline(source), nan=0.0)


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
) -> dict:
    """SSW behind one crossed pulse, by both methods, where it is resolved.

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
    noise_N : float
        Noise standard deviation of the crossed signal, N.

    Returns
    -------
    dict
        ``{"residual": (ssw_N, time_s, reason), "peak": (...), "scale": a, "misfit": N,
        "floor": N, "trailing_min_s": s, "candidate": N}``; ``reason`` is "" when the SSW
        is resolved (values NaN otherwise); ``misfit`` is the largest smoothed
        |signal - template| on the rising edge, ``floor`` the least resolved residual,
        ``candidate`` the residual maximum read, resolved or not, ``trailing_min_s`` the time of
        the crossed pulse's trailing minimum (NaN without a distinct bump).
    """
    # Imported here: scipy.interpolate and scipy.signal take most of a second to import,
    # and most jobs that import this module (for its tables' names) never measure.
    from scipy.interpolate import CubicSpline

    time = np.asarray(time_s, dtype=float)
    signal = np.asarray(force_N, dtype=float) - baseline_N
    ref_signal = np.asarray(reference_force_N, dtype=float) - reference_baseline_N
    nan = (math.nan, math.nan, "crossed pulse not sampled")
    result = {"residual": nan, "peak": nan, "scale": math.nan, "misfit": math.nan}
    result.update(floor=math.nan, trailing_min_s=math.nan, candidate=math.nan)
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
    smooth, noise_gain = _smoother(time, crossed_tau_s)
    residual = smooth(signal - template)
    # Measured on the smoothed residual, as the SSW is: the noise enters once, below.
    misfit = float(np.max(np.abs(residual[edge])))
    floor = RESOLVE_FACTOR * (misfit + NOISE_SIGMAS * noise_gain * noise_N)
    result.update(scale=scale, misfit=misfit, floor=floor)
    window = np.flatnonzero(time <= time[top] + WINDOW_TAUS * crossed_tau_s)
    prominence = max(MIN_PEAK_FRACTION * crossed_peak_N, MIN_PEAK_SNR * noise_gain * noise_N)
    smoothed = smooth(signal)
    bump = _distinct_bump(smoothed, top, int(window[-1]), prominence)
    unresolved = (math.nan, math.nan, NOT_RESOLVED)
    result.update(residual=unresolved, peak=unresolved)
    if bump is None:
        return result
    low, peak, far = bump
    best = low + int(np.argmax(residual[low : far + 1]))
    result.update(trailing_min_s=float(time[low]), candidate=float(residual[best]))
    if residual[best] > floor:
        result["residual"] = (float(residual[best]), float(time[best]), "")
        result["peak"] = (float(smoothed[peak]), float(time[peak]), "")
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


def _smoother(time, tau):
    """Quadratic Savitzky-Golay smoothing tau/2 long, and its gain on white noise."""
    from scipy.signal import savgol_coeffs, savgol_filter  # imported here: see measure_ssw

    dt = float(np.median(np.diff(time)))
    length = round(0.5 * tau / dt) | 1
    if not 5 <= length < len(time):
        return (lambda values: values), 1.0
    gain = math.sqrt(float(np.sum(savgol_coeffs(length, 2) ** 2)))
    return (lambda values: savgol_filter(values, length, 2)), gain


def _distinct_bump(smoothed, top: int, last: int, prominence: float):
    """The first local maximum after the crossed peak ``top`` (up to index ``last``)
    with at least ``prominence``: (trailing minimum, maximum, far base) indices, or None.

    Prominence is measured within [top, last], so the crossed pulse itself bounds the
    bump on the near side and the trailing minimum is the lowest point between them.
    """
    from scipy.signal import find_peaks  # imported here: see measure_ssw

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
        maximum behind the trailing minimum whether or not it clears the floor (NaN
        without a distinct bump), ``trailing_min_us`` the time of the
        crossed pulse's trailing minimum. Unresolved rows: ``ok`` False, reason
        :data:`NOT_RESOLVED`, ``ssw_N`` NaN.
    """
    pulses = apply_selection(pulses[pulses["estimator"] == estimator], selection)
    beads = sensor_beads(traces)
    context = {
        "bead_of": {"S1": beads[0], "S2": beads[-1]},
        "signals": {shot: (meta, t, forces) for shot, meta, t, forces in iter_shots(traces)},
        "lookup": {
            (row.source, row.model, row.N, row.shot, row.sensor, row.role): row
            for row in pulses.itertuples(index=False)
        },
        "references": _usable_references(pulses),
    }
    # The references of each (source, model, N, amplitude), in table order, found once.
    context["references_of"] = dict(
        list(context["references"].groupby(_REFERENCE_KEY, sort=False, dropna=False))
    )
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


def _usable_references(pulses: pd.DataFrame) -> pd.DataFrame:
    references = pulses[(pulses["role"] == "reference") & (pulses["sensor"] == "S2")]
    return references[is_ok(references)]


def _sensor_rows(shot, sensor: str, context: dict) -> list[dict]:
    """The two rows (one per method) of one collision shot at one sensor."""
    wave, first = _CROSSED[sensor]
    where = (shot.source, shot.model, shot.N, shot.shot)
    crossed = context["lookup"].get((*where, sensor, "crossed"))
    incident = context["lookup"].get((*where, first, "incident"))
    base = {
        "source": shot.source,
        "model": shot.model,
        "N": shot.N,
        "shot": shot.shot,
        "amplitude": shot.amplitude,
        "sensor": sensor,
        "bead": context["bead_of"][sensor],
        "wave": wave,
    }
    same = context["references_of"].get(tuple(getattr(shot, key) for key in _REFERENCE_KEY))
    same = context["references"].iloc[:0] if same is None else same
    reason = ""
    if crossed is None or not bool(crossed.ok):
        reason = "crossed pulse not measured"
    elif incident is None or not bool(incident.ok):
        reason = "incident pulse not measured"
    elif same.empty:
        reason = "no usable reference shot of this amplitude"
    if reason:
        return [_row(base, method, math.nan, math.nan, math.nan, reason) for method in SSW_METHODS]
    # The reference closest in size to the crossed pulse needs the least rescaling.
    reference = same.loc[(same["F_m_N"] - crossed.F_m_N).abs().idxmin()]
    result = _measure_at_sensor(shot.shot, sensor, crossed, reference, context)
    rows = []
    for method in SSW_METHODS:
        value, when, why = result[method]
        row = _row(base, method, incident.F_m_N, value, when, why)
        row.update(
            {
                "ssw_lag_us": (when - crossed.T_s) * 1e6,
                "F_crossed_N": crossed.F_m_N,
                "reference_shot": int(reference["shot"]),
                "template_scale": result["scale"],
                "template_misfit_N": result["misfit"],
                "ssw_floor_N": result["floor"],
                "trailing_min_us": result["trailing_min_s"] * 1e6,
                "ssw_candidate_N": result["candidate"],
            }
        )
        rows.append(row)
    return rows


def _measure_at_sensor(shot: int, sensor: str, crossed, reference, context: dict) -> dict:
    """:func:`measure_ssw` on the crossed signal at ``sensor`` against the reference
    shot's signal at S2 (the same distance from the launching end)."""
    _, time, forces = context["signals"][shot]
    _, ref_time, ref_forces = context["signals"][int(reference["shot"])]
    ref_force = ref_forces[context["bead_of"]["S2"]]
    force = forces[context["bead_of"][sensor]]
    baseline, noise = estimate_baseline(time, force)
    ref_baseline, _ = estimate_baseline(ref_time, ref_force)
    return measure_ssw(
        time,
        force,
        crossed.F_m_N,
        crossed.T_s,
        crossed.tau_s,
        ref_time,
        ref_force,
        reference["F_m_N"],
        reference["T_s"],
        baseline_N=baseline,
        reference_baseline_N=ref_baseline,
        noise_N=noise,
    )


def _row(base, method, f_m, value, when, reason) -> dict:
    ok = not reason
    return {
        **base,
        "F_m_N": f_m,
        "ssw_N": value if ok else math.nan,
        "ssw_time_us": when * 1e6 if ok else math.nan,
        "method": method,
        "ok": ok,
        "reason": reason,
    }


def ssw_fit_table(ssw: pd.DataFrame, method: str = "residual") -> pd.DataFrame:
    """SSW = slope x F_m through the origin, per source, model and N (``ssw_fits.csv``).

    Unweighted least squares of the ``ok`` rows of ``method``, standard error from the
    residual scatter (:func:`chain.analysis.regression.fit_proportional`); fewer than 2 points
    give NaN and ``n_points``.

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv`` rows (:func:`ssw_table`).
    method : {"residual", "peak"}
        Which SSW measurement to fit.

    Returns
    -------
    DataFrame
        ``source, model, N, method, slope, slope_stderr, n_points``; slope in N/N.
    """
    rows = []
    chosen = ssw[ssw["method"] == method]
    for (source, model, n_beads), group in chosen.groupby(["source", "model", "N"], sort=True):
        used = group[is_ok(group)]
        fit = fit_proportional(used["F_m_N"].to_numpy(float), used["ssw_N"].to_numpy(float))
        rows.append(
            {
                "source": source,
                "model": model,
                "N": int(n_beads),
                "method": method,
                "slope": fit.coefficient,
                "slope_stderr": fit.stderr,
                "n_points": fit.n_points,
            }
        )
    return pd.DataFrame(rows, columns=SSW_FIT_COLUMNS)


#: Columns of :func:`ssw_resolution_table` (summary key ``ssw_resolved``).
RESOLUTION_COLUMNS = ("source", "model", "N", "sensor", "resolved", "n_resolved", "n_total")


def ssw_resolution_table(ssw: pd.DataFrame, method: str = "residual") -> pd.DataFrame:
    """Is the SSW resolved at each sensor? One row per (source, model, N, sensor).

    Parameters
    ----------
    ssw : DataFrame
        ``ssw.csv`` rows (:func:`ssw_table`).
    method : {"residual", "peak"}
        Which measurement's rows to count.

    Returns
    -------
    DataFrame
        Columns :data:`RESOLUTION_COLUMNS`: ``n_resolved`` of ``n_total`` collision shots
        have a value (``ok``); ``resolved`` is True when at least half of them do.
    """
    rows = []
    chosen = ssw[ssw["method"] == method]
    for key, group in chosen.groupby(["source", "model", "N", "sensor"], sort=True):
        n_resolved, n_total = int(is_ok(group).sum()), len(group)
        rows.append(
            dict(zip(RESOLUTION_COLUMNS[:4], key))
            | {"resolved": n_total > 0 and 2 * n_resolved >= n_total}
            | {"n_resolved": n_resolved, "n_total": n_total}
        )
    table = pd.DataFrame(rows, columns=RESOLUTION_COLUMNS)
    table["N"] = table["N"].astype(int)
    return table


def ssw_parity_table(fits: pd.DataFrame, even: int = 26, odd: int = 25) -> pd.DataFrame:
    """SSW slope of the even chain over the odd one's, per source and model (the paper's
    claim: larger when the waves cross at a contact). NaN where either has no fit.

    Parameters
    ----------
    fits : DataFrame
        ``ssw_fits.csv`` rows (:func:`ssw_fit_table`).
    even, odd : int
        The two chains compared (the paper's 26 and 25).

    Returns
    -------
    DataFrame
        ``source, model, ratio`` for every (source, model) with both chains.
    """
    rows = []
    numeric = fits[fits["N"].astype(str).isin([str(even), str(odd)])]
    for (source, model), group in numeric.groupby(["source", "model"], sort=True):
        slopes = dict(zip(group["N"].astype(int), group["slope"].astype(float)))
        if even in slopes and odd in slopes:
            ratio = slopes[even] / slopes[odd] if slopes[odd] else math.nan
            rows.append({"source": source, "model": model, "ratio": ratio})
    return pd.DataFrame(rows, columns=["source", "model", "ratio"])
