"""Peaks of a sampled signal as scipy.signal defines them, bit for bit, without importing
scipy.signal: its import takes 0.25-0.4 s, most of an analysis job's start-up, for three
functions. :func:`find_peaks` is ``scipy.signal.find_peaks`` with its ``height``,
``distance`` and ``prominence`` rules (no window), :func:`peak_width` one peak's
``scipy.signal.peak_widths``; ``tests/test_peaks.py`` compares them with scipy's.
Signals are in any unit (N here), indices in samples.
"""

from __future__ import annotations

import math

import numpy as np


def local_maxima(x: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of ``x`` as find_peaks defines them: a run of equal
    values higher than both neighbours, not touching either end, taken at its middle
    sample (the left one of two)."""
    if x.size < 3:
        return np.zeros(0, dtype=np.int64)
    starts = np.r_[0, np.flatnonzero(np.diff(x) != 0) + 1]
    ends = np.r_[starts[1:] - 1, x.size - 1]
    level = x[starts]
    inner = np.arange(1, starts.size - 1)
    peak = (level[inner - 1] < level[inner]) & (level[inner + 1] < level[inner])
    runs = inner[peak]
    return (starts[runs] + ends[runs]) // 2


def peak_prominence(x: np.ndarray, peak: int) -> tuple[float, int, int]:
    """find_peaks' prominence of ``x[peak]`` (no window) and its left and right bases:
    its height above the higher of the lowest points between it and the nearest higher
    sample on each side (or the end of ``x``); of equal lowest points, the nearest."""
    top = x[peak]
    higher_left = np.flatnonzero(x[:peak] > top)
    higher_right = np.flatnonzero(x[peak + 1 :] > top)
    start = int(higher_left[-1]) + 1 if higher_left.size else 0
    stop = peak + 1 + int(higher_right[0]) if higher_right.size else x.size
    left = x[start : peak + 1]
    left_base = start + left.size - 1 - int(np.argmin(left[::-1]))
    right_base = peak + int(np.argmin(x[peak:stop]))
    return top - max(x[left_base], x[right_base]), left_base, right_base


def find_peaks(x, *, height=None, distance=None, prominence=None):
    """``scipy.signal.find_peaks(x, height=, distance=, prominence=)``: the peak indices
    and, with ``prominence``, {"prominences", "left_bases", "right_bases"} of them.

    Parameters
    ----------
    x : array
        The signal.
    height : float, optional
        Least height of a peak, in the signal's unit.
    distance : float, optional
        Least spacing of peaks, samples (>= 1): of closer ones the highest is kept.
    prominence : float, optional
        Least prominence, in the signal's unit.
    """
    x = np.asarray(x, dtype=float)
    peaks = local_maxima(x)
    if height is not None:
        peaks = peaks[height <= x[peaks]]
    if distance is not None:
        peaks = peaks[_spaced(peaks, x[peaks], math.ceil(distance))]
    if prominence is None:
        return peaks, {}
    found = np.array([peak_prominence(x, int(peak)) for peak in peaks]).reshape(-1, 3)
    keep = prominence <= found[:, 0]
    left, right = found[keep, 1:].astype(np.int64).T
    return peaks[keep], {"prominences": found[keep, 0], "left_bases": left, "right_bases": right}


def _spaced(peaks: np.ndarray, priority: np.ndarray, distance: int) -> np.ndarray:
    """Which ``peaks`` find_peaks keeps at least ``distance`` samples apart: from the
    highest down, each removes the lower ones closer than that (its order of ties)."""
    keep = np.ones(peaks.size, dtype=bool)
    for j in np.argsort(priority)[::-1]:
        if keep[j]:
            near = np.abs(peaks - peaks[j]) < distance
            near[j] = False
            keep[near] = False
    return keep


def peak_width(x: np.ndarray, peak: int, rel_height: float = 0.5) -> float:
    """``scipy.signal.peak_widths(x, [peak], rel_height)[0][0]``: the width of a peak,
    samples, at ``rel_height`` of its prominence below its top, interpolated between
    samples and bounded by its bases."""
    height_of_top, left_base, right_base = peak_prominence(x, peak)
    height = x[peak] - height_of_top * rel_height
    below = np.flatnonzero(x[left_base + 1 : peak + 1] <= height)
    i = left_base + 1 + int(below[-1]) if below.size else left_base
    left = float(i)
    if x[i] < height:
        left += (height - x[i]) / (x[i + 1] - x[i])
    below = np.flatnonzero(x[peak:right_base] <= height)
    i = peak + int(below[0]) if below.size else right_base
    right = float(i)
    if x[i] < height:
        right -= (height - x[i]) / (x[i - 1] - x[i])
    return right - left
