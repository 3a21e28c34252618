"""Quadratic Savitzky-Golay smoothing as the analysis uses it: the coefficients (cached,
as every pulse of a sweep sampled alike asks for the same few), the filter on just the
samples that are read, its gain on white noise, and the tau/2 smoothing of the SSW.

scipy.ndimage is imported where used, as is scipy.signal, which takes 0.25-0.4 s to
import: the coefficients are its own formula (:func:`savgol_coeffs`), and only a window
that reaches a record's ends takes its filter.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np


@lru_cache(maxsize=64)
def savgol_dot_coefficients(length: int, dt: float) -> tuple[np.ndarray, ...]:
    """Quadratic Savitzky-Golay coefficients of the value, slope (1/s) and curvature
    (1/s^2) at the centre of ``length`` samples ``dt`` s apart (for ``np.dot``;
    read-only).

    Parameters
    ----------
    length : int
        Odd number of samples.
    dt : float
        Sampling interval, s.
    """
    coefficients = tuple(savgol_coeffs(length, deriv=d, delta=dt, use="dot") for d in (0, 1, 2))
    for c in coefficients:
        c.flags.writeable = False
    return coefficients


@lru_cache(maxsize=64)
def smoothing_coefficients(length: int) -> np.ndarray:
    """Coefficients of ``scipy.signal.savgol_filter(x, length, 2)`` (read-only), for an
    odd window ``length`` in samples."""
    coefficients = savgol_coeffs(length)
    coefficients.flags.writeable = False
    return coefficients


def savgol_coeffs(length: int, deriv: int = 0, delta: float = 1.0, use: str = "conv"):
    """``scipy.signal.savgol_coeffs(length, 2, deriv, delta, use=use)`` for an odd
    ``length`` (samples) and ``delta`` in s, by scipy 1.17's own steps (the minimum-norm
    least-squares solution of the Vandermonde system), so the same bits
    (``tests/test_peaks.py``)."""
    from scipy.linalg import lstsq  # loaded with scipy.optimize, which the fits import

    half = length // 2
    x = np.arange(-half, length - half, dtype=np.float64)
    x = x[::-1] if use == "conv" else x
    design = x ** np.arange(3, dtype=np.float64).reshape(-1, 1)
    wanted = np.zeros(3)
    wanted[deriv] = float(math.factorial(deriv)) / (delta**deriv)
    return lstsq(design, wanted, cond=np.finfo(np.float64).eps * max(design.shape))[0]


@lru_cache(maxsize=64)
def noise_gain(length: int) -> float:
    """Standard deviation of ``savgol_filter(x, length, 2)`` (odd ``length``, samples) on
    white noise of unit standard deviation (the root sum of squares of its coefficients)."""
    return math.sqrt(float(np.sum(smoothing_coefficients(length) ** 2)))


def smoothed_interior(signal: np.ndarray, length: int, lo: int, hi: int) -> np.ndarray:
    """``savgol_filter(signal, length, 2)[lo:hi]`` for ``length // 2 <= lo < hi <=
    len(signal) - length // 2``, where every window lies inside the signal.

    The same convolution as the filter's on just the samples these windows cover (the
    filter's polynomial fits at the edges are never read), so the same values, in the
    signal's unit.

    Parameters
    ----------
    signal : array
        Samples, any unit (N here).
    length : int
        Odd window length of the quadratic filter, samples.
    lo, hi : int
        The sample range wanted, [lo, hi).
    """
    from scipy.ndimage import convolve1d

    half = length // 2
    part = signal[lo - half : hi + half]
    return convolve1d(part, smoothing_coefficients(length), mode="constant")[half : half + hi - lo]


def smoother(time_s, tau_s: float, lo: int, hi: int):
    """Quadratic Savitzky-Golay smoothing tau/2 long that is right on samples [lo, hi):
    (a function of an array of ``len(time_s)`` values that returns it smoothed, its
    :func:`noise_gain`).

    Where no window of [lo, hi) reaches the record's ends, only those samples are
    smoothed (:func:`smoothed_interior`: the filter's own values, bit for bit) and the
    others are NaN; else the whole record is, edges included. Shorter than 5 samples or
    than the record, the smoothing does nothing (gain 1).

    Parameters
    ----------
    time_s : array
        Sample times, s, evenly spaced.
    tau_s : float
        Pulse time scale, s.
    lo, hi : int
        The samples that will be read, [lo, hi).
    """
    dt = float(np.median(np.diff(time_s)))
    length = round(0.5 * tau_s / dt) | 1
    if not 5 <= length < len(time_s):
        return (lambda values: values), 1.0
    if not length // 2 <= lo < hi <= len(time_s) - length // 2:
        from scipy.signal import savgol_filter  # its edges' polynomial fits

        return (lambda values: savgol_filter(values, length, 2)), noise_gain(length)

    def smooth(values):
        out = np.full(len(values), math.nan)
        out[lo:hi] = smoothed_interior(values, length, lo, hi)
        return out

    return smooth, noise_gain(length)
