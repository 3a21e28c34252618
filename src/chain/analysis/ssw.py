"""Secondary solitary waves (SSW): the small waves born where the two pulses crossed.

After the crossing each wave is followed by a secondary wave. At the paper's sensor
positions it has not yet separated from the crossed pulse: in simulations it is a
shoulder on the trailing edge. Two measurements, one row each in ``ssw.csv``:

``residual`` (default)
    The reference pulse read at the same distance from the launching end (the
    reference shot of the same amplitude at S2: for LSTW crossed at S2 that is the same
    sensor; for RSTW crossed at S1 the symmetric sensor placement makes S2 the same
    distance from its launching end) is turned into a solitary wave of the crossed
    pulse's size by the Hertz self-similarity -- force scale a, time scale a^(-1/6) --
    and aligned on the crossed pulse by least squares on its rising edge and top
    (from T - tau to its highest sample, which the trailing SSW does not reach), a and
    the time shift free. The SSW amplitude is the largest value of crossed signal minus this
    template from the crossed pulse's peak to :data:`WINDOW_TAUS` tau after it,
    after a quadratic Savitzky-Golay smoothing tau/2 long (the SSW is about tau wide,
    the noise is not). With no SSW it is ~0 (a few noise sigma / sqrt(tau/2 samples)).
``peak``
    A distinct local maximum of the (smoothed) crossed signal in the same window, its
    height above the baseline; flagged ``ok`` False where there is none (the shoulder
    case).

:func:`ssw_fit_table` fits SSW = slope x F_m through the origin (Fig. 5).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline
from scipy.optimize import least_squares
from scipy.signal import find_peaks, savgol_coeffs, savgol_filter

from chain.analysis.pulses import estimate_baseline
from chain.analysis.regression import fit_proportional
from chain.analysis.rows import is_ok
from chain.analysis.selection import apply_selection
from chain.traces import iter_shots, sensor_beads

#: The SSW is looked for from the crossed pulse's peak to this many tau after it.
WINDOW_TAUS = 6.0

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
    """SSW behind one crossed pulse, by both methods.

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
        ``{"residual": (ssw_N, time_s, reason), "peak": (...), "scale": a,
        "misfit": N}``; ``reason`` is "" when the value is valid (NaN values otherwise);
        ``misfit`` is the largest |template - signal| on the rising edge used for the
        alignment.
    """
    time = np.asarray(time_s, dtype=float)
    signal = np.asarray(force_N, dtype=float) - baseline_N
    ref_time = np.asarray(reference_time_s, dtype=float)
    ref_signal = np.asarray(reference_force_N, dtype=float) - reference_baseline_N
    dt = float(np.median(np.diff(time)))
    tau, arrival = crossed_tau_s, crossed_arrival_s
    # Rising edge and top of the crossed pulse: untouched by what trails it.
    near = np.flatnonzero(np.abs(time - arrival) < tau)
    if near.size < 6:
        nan = (math.nan, math.nan, "crossed pulse not sampled")
        return {"residual": nan, "peak": nan, "scale": math.nan, "misfit": math.nan}
    top = int(near[np.argmax(signal[near])])
    edge = slice(int(near[0]), top + 1)
    spline = CubicSpline(ref_time, ref_signal, extrapolate=False)

    def misfit(params):
        scale, shift = params
        return _template(spline, time[edge], scale, shift, reference_arrival_s) - signal[edge]

    start = (crossed_peak_N / reference_peak_N, arrival)
    solution = least_squares(
        misfit, start, x_scale=(0.01, 0.01 * tau), bounds=([0, -np.inf], np.inf)
    )
    scale, shift = solution.x
    # How well a solitary wave matches the crossed pulse where no SSW can be: a floor
    # below which an SSW amplitude means nothing.
    edge_misfit = float(np.max(np.abs(solution.fun)))
    template = _template(spline, time, scale, shift, reference_arrival_s)
    window = (time >= time[top]) & (time <= time[top] + WINDOW_TAUS * tau)
    length = round(0.5 * tau / dt) | 1
    smoothing = 5 <= length < len(time)

    def smooth(values):
        return savgol_filter(values, length, 2) if smoothing else values

    noise_gain = math.sqrt(float(np.sum(savgol_coeffs(length, 2) ** 2))) if smoothing else 1.0
    residual = smooth(signal - template)
    indices = np.flatnonzero(window)
    best = int(indices[np.argmax(residual[indices])])
    result = {
        "residual": (float(residual[best]), float(time[best]), ""),
        "scale": float(scale),
        "misfit": edge_misfit,
    }
    # Distinct peaks: local maxima of the smoothed signal from the main pulse's rise to
    # the end of the window, the main pulse's own maximum (the largest) excluded.
    region = np.arange(int(near[0]), int(indices[-1]) + 1)
    smoothed = smooth(signal)[region]
    prominence = max(MIN_PEAK_FRACTION * crossed_peak_N, MIN_PEAK_SNR * noise_gain * noise_N)
    peaks, _ = find_peaks(smoothed, prominence=prominence)
    peaks = peaks[peaks > np.argmax(smoothed)]
    if peaks.size:
        first = int(peaks[0])
        result["peak"] = (float(smoothed[first]), float(time[region[first]]), "")
    else:
        result["peak"] = (math.nan, math.nan, "no distinct SSW peak")
    return result


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
        ``pulses.csv`` rows of these traces (:func:`chain.analysis.pulses.pulse_table`).
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
        ``template_misfit_N`` the largest |template - signal| on the rising edge (the
        floor of the residual method).
    """
    pulses = apply_selection(pulses[pulses["estimator"] == estimator], selection)
    beads = sensor_beads(traces)
    bead_of = {"S1": beads[0], "S2": beads[-1]}
    signals = {shot: (meta, time, forces) for shot, meta, time, forces in iter_shots(traces)}
    keys = ["source", "model", "N"]
    rows = []
    lookup = {
        (row.source, row.model, row.N, row.shot, row.sensor, row.role): row
        for row in pulses.itertuples(index=False)
    }
    references = pulses[(pulses["role"] == "reference") & (pulses["sensor"] == "S2")]
    references = references[is_ok(references)]
    collisions = pulses[pulses["kind"] == "collision"][[*keys, "shot", "amplitude"]]
    for shot in collisions.drop_duplicates().itertuples(index=False):
        if shot.shot not in signals:
            continue
        meta, time, forces = signals[shot.shot]
        if (meta["source"], meta["model"], meta["N"]) != (shot.source, shot.model, shot.N):
            continue
        for sensor, (wave, first) in _CROSSED.items():
            where = (shot.source, shot.model, shot.N, shot.shot)
            crossed = lookup.get((*where, sensor, "crossed"))
            incident = lookup.get((*where, first, "incident"))
            base = {
                "source": shot.source,
                "model": shot.model,
                "N": shot.N,
                "shot": shot.shot,
                "amplitude": shot.amplitude,
                "sensor": sensor,
                "bead": bead_of[sensor],
                "wave": wave,
            }
            same = references[
                (references["source"] == shot.source)
                & (references["model"] == shot.model)
                & (references["N"] == shot.N)
                & (references["amplitude"] == shot.amplitude)
            ]
            reason = ""
            if crossed is None or not bool(crossed.ok):
                reason = "crossed pulse not measured"
            elif incident is None or not bool(incident.ok):
                reason = "incident pulse not measured"
            elif same.empty:
                reason = "no usable reference shot of this amplitude"
            if reason:
                for method in SSW_METHODS:
                    rows.append(_row(base, method, math.nan, math.nan, math.nan, reason))
                continue
            # The reference closest in size to the crossed pulse needs the least rescaling.
            reference = same.loc[(same["F_m_N"] - crossed.F_m_N).abs().idxmin()]
            _, ref_time, ref_forces = signals[int(reference["shot"])]
            ref_force = ref_forces[bead_of["S2"]]
            force = forces[bead_of[sensor]]
            baseline, noise = estimate_baseline(time, force)
            ref_baseline, _ = estimate_baseline(ref_time, ref_force)
            result = measure_ssw(
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
                    }
                )
                rows.append(row)
    return pd.DataFrame(rows, columns=SSW_COLUMNS)


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
