"""Pulse analysis of sampled force signals: baseline, segmentation, amplitude and timing.

A sensor signal of a collision shot holds two main pulses (the incident wave, then the
wave that crossed it); a reference shot holds one. :func:`find_pulses` locates them and
splits neighbours at the minimum between them; :func:`fit_pulse` measures one pulse
with one of the :data:`ESTIMATORS`:

``fit_full`` (the paper's method)
    least squares of F_m cos^6((t - T)/tau) on -tau < t - T < tau, the window
    re-selected from the new (T, tau) until the set of samples no longer changes (or,
    with noise, cycles between windows whose fits agree within 2 standard errors);
    initial tau from the full width at half maximum, FWHM = 2 tau arccos(2^(-1/6));
``peak``
    parabolic interpolation of the maximum: the vertex of the least-squares parabola
    through the samples within tau/4 of the largest one (the 3-point parabola when the
    pulse spans few samples; more samples average the noise over the flat top, where
    cos^6 is a parabola to 0.2 %); tau from the full width at half maximum;
``fit_rise``
    the same fit as ``fit_full`` on the rising half only, -tau < t - T <= 0 (blind to
    whatever trails the peak).

A measurement that cannot be made gives a :class:`PulseFit` with ``ok=False`` and a
``reason``, never an exception. :func:`chain.analysis.pulse_rows.pulse_table` applies
both to every sensor signal of a trace table (the rows of ``pulses.csv``).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from chain.analysis.cos6 import (  # noqa: F401 (cos6_model: a public name here too)
    Cos6Evaluations,
    cos6_model,
)
from chain.analysis.peaks import find_peaks, peak_width
from chain.analysis.smoothing import savgol_dot_coefficients, smoothed_interior
from chain.errors import ParameterError

#: Names of the amplitude/arrival-time estimators, the paper's first.
ESTIMATORS = ("fit_full", "peak", "fit_rise")

#: FWHM of cos^6((t - T)/tau) divided by tau: 2 arccos(2^(-1/6)) = 0.9416.
COS6_FWHM_PER_TAU = 2.0 * math.acos(2.0 ** (-1.0 / 6.0))

#: Default prominence of a main pulse, as a fraction of the largest pulse: main pulses
#: are of similar size, noise bumps and secondary waves are far smaller.
DEFAULT_REL_PROMINENCE = 0.2

#: Default detection threshold in units of the noise standard deviation: the largest
#: of ~10^4 Gaussian samples stays below 5 sigma.
DEFAULT_MIN_SNR = 8.0

#: Fewest samples a fit window may hold (three parameters plus a few degrees of freedom).
MIN_FIT_SAMPLES = 6

#: Fits of a window cycle that agree within this many standard errors count as stable.
CYCLE_TOLERANCE = 2.0

#: Longest sequence of window re-selections before a fit is declared unstable.
MAX_WINDOW_ITERATIONS = 30

#: A segment reaches this many FWHM beyond a pulse's peak on its free sides
#: (the cos^6 hump ends at pi tau / 2 = 1.67 FWHM from the peak).
SEGMENT_HALF_WIDTH_FWHM = 2.0

#: Fraction of the largest excursion below which a sample counts as "quiet" (baseline).
QUIET_FRACTION = 0.05


@dataclass(frozen=True)
class PulseFit:
    """Amplitude and timing of one pulse.

    Attributes
    ----------
    peak_force : float
        F_m, N, above the baseline.
    arrival_time : float
        T, time of the peak, s (same origin as the input times).
    tau : float
        Time scale of F_m cos^6((t - T)/tau), s.
    peak_force_stderr, arrival_time_stderr, tau_stderr : float
        Standard errors, N, s, s (from the fit covariance scaled by the residual
        variance, or from the noise level for ``peak``); NaN when unknown.
    ok : bool
        False when the measurement failed; the values are then NaN.
    reason : str
        Why it failed ("" when ok).
    n_samples : int
        Samples used (final fit window, or the smoothing window for ``peak``).
    """

    peak_force: float
    arrival_time: float
    tau: float
    peak_force_stderr: float
    arrival_time_stderr: float
    tau_stderr: float
    ok: bool = True
    reason: str = ""
    n_samples: int = 0

    @classmethod
    def failed(cls, reason: str) -> PulseFit:
        """A flagged result with NaN values."""
        nan = math.nan
        return cls(nan, nan, nan, nan, nan, nan, ok=False, reason=reason, n_samples=0)


@dataclass(frozen=True)
class PulseSegment:
    """Index range [start, stop) of one pulse in a signal, and the index of its peak."""

    start: int
    stop: int
    peak: int

    @property
    def slice(self) -> slice:
        return slice(self.start, self.stop)


def estimate_baseline(time_s, force_N) -> tuple[float, float]:
    """Baseline offset and noise level of a signal, from its pre-pulse part.

    The pre-pulse part ends well before the foot of the first pulse: the first sample
    above half the largest excursion is found, then the last quiet sample before it
    (below :data:`QUIET_FRACTION` of the excursion); the rise between the two spans
    0.45 tau for a cos^6 pulse and the foot below it 0.65 tau, so the part is cut two
    rises earlier. With fewer than 8 samples there, all quiet samples of the signal
    are used instead.

    Parameters
    ----------
    time_s : array
        Times, s (unused; kept for a uniform signature).
    force_N : array
        Signal, N.

    Returns
    -------
    baseline_N : float
        Median of the pre-pulse part, N.
    noise_N : float
        Its standard deviation (1.4826 x median absolute deviation), N, or the one from
        successive differences of the whole signal if that is larger.
    """
    force = np.asarray(force_N, dtype=float)
    rough = float(np.median(force))
    excursion = float(force.max()) - rough
    quiet = force
    if excursion > 0:
        half = np.flatnonzero(force - rough > 0.5 * excursion)
        first_half = int(half[0])
        below = np.flatnonzero(force[:first_half] - rough <= QUIET_FRACTION * excursion)
        if below.size:
            foot = int(below[-1])
            end = foot - 2 * (first_half - foot)
            if end >= 8:
                quiet = force[:end]
            else:
                quiet = force[np.abs(force - rough) <= QUIET_FRACTION * excursion]
    baseline = float(np.median(quiet))
    noise = 1.4826 * float(np.median(np.abs(quiet - baseline)))
    # On a signal with no pulse the "quiet" samples are only those near the median, and
    # their spread underestimates the noise. Successive differences of the whole signal
    # give a second, robust estimate (pulses are smooth on the sampling scale, so they
    # barely move the median of the differences); the larger of the two is kept.
    if force.size > 2:
        steps = np.diff(force)
        noise = max(noise, 1.4826 * float(np.median(np.abs(steps - np.median(steps)))) / 2**0.5)
    return baseline, noise


def find_pulses(
    time_s,
    force_N,
    max_pulses: int = 2,
    *,
    baseline_N: float | None = None,
    noise_N: float | None = None,
    rel_prominence: float = DEFAULT_REL_PROMINENCE,
    min_snr: float = DEFAULT_MIN_SNR,
    min_height_N: float = 0.0,
) -> list[PulseSegment]:
    """The main pulses of a signal, in time order, as index ranges (empty when no pulse
    clears the thresholds).

    Peaks are found as :func:`scipy.signal.find_peaks` finds them
    (:func:`chain.analysis.peaks.find_peaks`); a main pulse has a prominence
    of at least ``rel_prominence`` times the largest excursion and a height above
    ``max(min_snr * noise_N, min_height_N)``. The ``max_pulses`` most prominent are
    kept; maxima closer than the full width at half maximum of the largest pulse count
    as one (ties of a quantised top). Neighbours are split at the minimum of the signal
    between their peaks; a free side extends :data:`SEGMENT_HALF_WIDTH_FWHM` widths at half maximum.

    Parameters
    ----------
    time_s : array
        Times, s, increasing.
    force_N : array
        Signal, N.
    max_pulses : int
        Most pulses to return.
    baseline_N, noise_N : float, optional
        Baseline offset and noise standard deviation, N; estimated by
        :func:`estimate_baseline` when not given.
    rel_prominence : float
        Least prominence of a pulse, as a fraction of the largest excursion.
    min_snr : float
        Least height of a pulse above the baseline, in noise standard deviations.
    min_height_N : float
        Least height above the baseline, N.
    """
    time, force = _as_signal(time_s, force_N)
    baseline_N, noise_N = _baseline(time, force, baseline_N, noise_N)
    signal = force - baseline_N
    largest = float(signal.max())
    threshold = max(min_snr * noise_N, min_height_N)
    if not largest > threshold or largest <= 0:
        return []
    # Samples of one top tie when the data are quantised (each then has the full
    # prominence): maxima closer than the width at half maximum of the largest pulse
    # belong to one pulse, and pulses that close could not be told apart anyway.
    fwhm = peak_width(signal, int(np.argmax(signal)))
    peaks, properties = find_peaks(
        signal, height=threshold, prominence=rel_prominence * largest, distance=max(1.0, fwhm)
    )
    if peaks.size == 0:
        return []
    strongest = np.argsort(properties["prominences"])[::-1][:max_pulses]
    peaks = np.sort(peaks[strongest])
    widths = [peak_width(signal, peak) for peak in peaks]
    segments = []
    for i, peak in enumerate(peaks):
        reach = math.ceil(SEGMENT_HALF_WIDTH_FWHM * float(widths[i]))
        start = max(0, peak - reach)
        stop = min(len(signal), peak + reach + 1)
        if i > 0:
            start = max(start, peaks[i - 1] + int(np.argmin(signal[peaks[i - 1] : peak])))
        if i + 1 < len(peaks):
            stop = min(stop, peak + int(np.argmin(signal[peak : peaks[i + 1]])) + 1)
        segments.append(PulseSegment(int(start), int(stop), int(peak)))
    return segments


def fit_pulse(
    time_s,
    force_N,
    estimator: str = "fit_full",
    *,
    baseline_N: float | None = None,
    noise_N: float | None = None,
) -> PulseFit:
    """Amplitude, arrival time and width of the largest pulse of a signal, ``ok=False``
    with a reason when it cannot be measured.

    Pass one segment of :func:`find_pulses` (``time_s[seg.slice]``...) to measure a
    pulse that has neighbours, with the baseline of the whole signal.

    Parameters
    ----------
    time_s : array
        Times, s, increasing and evenly sampled.
    force_N : array
        Signal, N.
    estimator : {"fit_full", "peak", "fit_rise"}
        See the module docstring.
    baseline_N, noise_N : float, optional
        Baseline offset and noise standard deviation, N; estimated from the signal by
        :func:`estimate_baseline` when not given.
    """
    if estimator not in ESTIMATORS:
        raise ParameterError(f"estimator must be one of {ESTIMATORS}, got {estimator!r}")
    fits = measure_pulse(time_s, force_N, (estimator,), baseline_N=baseline_N, noise_N=noise_N)
    return fits[estimator]


def measure_pulse(
    time_s,
    force_N,
    estimators=ESTIMATORS,
    *,
    baseline_N: float | None = None,
    noise_N: float | None = None,
) -> dict[str, PulseFit]:
    """The largest pulse of a signal measured with each of several ``estimators``
    (names from :data:`ESTIMATORS`): what :func:`fit_pulse`, whose other parameters it
    takes (s, N), gives for each, with the checks, the baseline and the width at half
    maximum (the initial tau) found once for all. Returns {estimator: PulseFit}."""
    unknown = [e for e in estimators if e not in ESTIMATORS]
    if unknown:
        raise ParameterError(f"estimators must be among {ESTIMATORS}, got {unknown}")
    time, force = _as_signal(time_s, force_N)

    def failed(reason: str) -> dict[str, PulseFit]:
        return dict.fromkeys(estimators, PulseFit.failed(reason))

    if len(time) < MIN_FIT_SAMPLES:
        return failed(f"fewer than {MIN_FIT_SAMPLES} samples")
    if not (np.all(np.isfinite(time)) and np.all(np.isfinite(force))):
        return failed("non-finite samples")
    baseline_N, noise_N = _baseline(time, force, baseline_N, noise_N)
    signal = force - baseline_N
    peak = int(np.argmax(signal))
    if not signal[peak] > 0:
        return failed("no positive pulse")
    half_width = peak_width(signal, peak)
    if not half_width > 0:
        return failed("pulse width not measurable")
    dt = float(np.median(np.diff(time)))
    tau0 = half_width * dt / COS6_FWHM_PER_TAU
    return {
        estimator: _peak_estimate(time, signal, peak, tau0, noise_N, dt)
        if estimator == "peak"
        else _iterated_fit(time, signal, peak, tau0, rising_only=estimator == "fit_rise")
        for estimator in estimators
    }


def _baseline(time, force, baseline_N, noise_N) -> tuple[float, float]:
    """(baseline, noise), N: those given, or :func:`estimate_baseline`'s where None."""
    if baseline_N is None or noise_N is None:
        estimated = estimate_baseline(time, force)
        baseline_N = estimated[0] if baseline_N is None else baseline_N
        noise_N = estimated[1] if noise_N is None else noise_N
    return baseline_N, noise_N


def _as_signal(time_s, force_N) -> tuple[np.ndarray, np.ndarray]:
    time = np.asarray(time_s, dtype=float)
    force = np.asarray(force_N, dtype=float)
    if time.ndim != 1 or time.shape != force.shape:
        raise ParameterError(
            f"time_s and force_N must be 1-D arrays of one length, got {time.shape} "
            f"and {force.shape}"
        )
    if time.size == 0:
        raise ParameterError("time_s and force_N are empty")
    return time, force


def _window(time, arrival, tau, rising_only: bool) -> tuple[int, int]:
    start = int(np.searchsorted(time, arrival - tau, side="right"))
    if rising_only:
        return start, int(np.searchsorted(time, arrival, side="right"))
    return start, int(np.searchsorted(time, arrival + tau, side="left"))


def _iterated_fit(time, signal, peak, tau0, *, rising_only: bool) -> PulseFit:
    """Fit F_m cos^6 on the window the parameters define, until the window is stable.

    With noise the window map can cycle between windows a sample apart; the cycle is
    accepted as stable when its fits agree within :data:`CYCLE_TOLERANCE` standard
    errors (the window no longer moves the estimate beyond the noise), and the fit on
    the most samples is returned.
    """
    from scipy.optimize import OptimizeWarning, curve_fit  # see chain.analysis.smoothing

    params = np.array([signal[peak], time[peak], tau0])
    windows = [_window(time, params[1], params[2], rising_only)]
    fits = []
    for _ in range(MAX_WINDOW_ITERATIONS):
        start, stop = windows[-1]
        if stop - start < MIN_FIT_SAMPLES:
            return PulseFit.failed(f"fit window holds {max(stop - start, 0)} samples")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error", OptimizeWarning)
                evaluations = Cos6Evaluations()
                params, covariance = curve_fit(
                    evaluations.model,
                    time[start:stop],
                    signal[start:stop],
                    p0=params,
                    jac=evaluations.jacobian,
                    col_deriv=True,
                    maxfev=2000,
                )
        except (RuntimeError, OptimizeWarning, ValueError) as error:
            return PulseFit.failed(f"fit did not converge ({error})")
        force, arrival, tau = params
        if not (force > 0 and tau > 0 and time[0] <= arrival <= time[-1]):
            return PulseFit.failed("fit left the segment")
        if tau > time[-1] - time[0]:
            return PulseFit.failed("fitted tau longer than the segment")
        errors = np.sqrt(np.diag(covariance))
        if not np.all(np.isfinite(errors)):
            return PulseFit.failed("covariance not estimable")
        fits.append(PulseFit(*map(float, (force, arrival, tau, *errors)), n_samples=stop - start))
        window = _window(time, arrival, tau, rising_only)
        if window == windows[-1]:
            return fits[-1]
        if window in windows:
            cycle = fits[windows.index(window) :]
            values = np.array([(f.peak_force, f.arrival_time, f.tau) for f in cycle])
            errors = np.array(
                [(f.peak_force_stderr, f.arrival_time_stderr, f.tau_stderr) for f in cycle]
            )
            if np.all(np.ptp(values, axis=0) <= CYCLE_TOLERANCE * errors.max(axis=0)):
                return max(cycle, key=lambda f: f.n_samples)
            return PulseFit.failed("fit window oscillates")
        windows.append(window)
    return PulseFit.failed(f"fit window not stable after {MAX_WINDOW_ITERATIONS} iterations")


def _peak_estimate(time, signal, peak, tau0, noise, dt) -> PulseFit:
    """Vertex of the least-squares parabola (quadratic Savitzky-Golay) through the
    samples within tau/4 of the maximum (see the module docstring). ``peak`` is the
    largest sample, ``tau0`` tau from its width at half maximum (s), also the value
    returned; ``dt`` the sampling interval, s."""
    length = max(round(0.5 * tau0 / dt) | 1, 3)
    half = length // 2
    lo, hi = max(peak - half, half), min(peak + half + 1, len(signal) - half)
    if hi <= lo:
        return PulseFit.failed("peak at the segment edge")
    if len(signal) > length:
        centre = lo + int(np.argmax(smoothed_interior(signal, length, lo, hi)))
    else:
        centre = lo + int(np.argmax(signal[lo:hi]))
    coefficients = savgol_dot_coefficients(length, dt)
    for _ in range(2):  # re-centre once on the sample nearest the vertex
        around = signal[centre - half : centre + half + 1]
        value, slope, curvature = (float(np.dot(c, around)) for c in coefficients)
        if not curvature < 0:
            return PulseFit.failed("peak not a maximum")
        offset = -slope / curvature  # s
        step = round(offset / dt)
        if step == 0 or not half <= centre + step < len(signal) - half:
            break
        centre += step
    if abs(offset) > half * dt:
        return PulseFit.failed("peak vertex outside the fitted samples")
    peak_value = value - 0.5 * slope**2 / curvature
    # Noise propagation: the value carries the filter's noise gain; the vertex moves by
    # the slope's noise over the curvature; each half-maximum crossing moves by
    # noise / |slope|, and |dF/dt| of cos^6 at half maximum is 1.527 F_m / tau.
    value_error = noise * math.sqrt(float(np.sum(coefficients[0] ** 2)))
    time_error = noise * math.sqrt(float(np.sum(coefficients[1] ** 2))) / abs(curvature)
    tau_error = math.sqrt(2.0) * noise / (1.527 * peak_value / tau0) / COS6_FWHM_PER_TAU
    return PulseFit(
        float(peak_value),
        float(time[centre] + offset),
        float(tau0),
        float(value_error),
        float(time_error),
        float(tau_error),
        n_samples=length,
    )
