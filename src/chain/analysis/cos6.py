"""The pulse shape the paper fits, F_m cos^6((t - T)/tau), and its Jacobian.

Functions of time (s) and of the three parameters F_m (N), T (s), tau (s), for the
least-squares fits of :mod:`chain.analysis.pulses`.
"""

from __future__ import annotations

import numpy as np


def cos6_model(time_s, peak_force_N: float, arrival_time_s: float, tau_s: float):
    """F_m cos^6((t - T)/tau) without the cut-off outside the hump (fits use |t-T| < tau), N.

    Parameters
    ----------
    time_s : array
        Times, s.
    peak_force_N, arrival_time_s, tau_s : float
        F_m (N), T (s), tau (s).
    """
    return peak_force_N * np.cos((np.asarray(time_s) - arrival_time_s) / tau_s) ** 6


class Cos6Evaluations:
    """:func:`cos6_model` and its Jacobian on one fit window, for ``curve_fit``
    (``evaluations.model`` and ``evaluations.jacobian`` with ``col_deriv=True``).

    MINPACK asks for the Jacobian at the point where it last evaluated the model (the
    step it accepted), so the phase, its cosine and cos^6 of that evaluation are kept
    and reused: the same operations on the same numbers, hence the same bits, in fewer
    passes over the window. The Jacobian is returned row-wise (``col_deriv=True``),
    which MINPACK reads as the same matrix without a transpose.
    """

    def __init__(self):
        self._point = None
        self._parts = None

    def _phase_parts(self, time, peak_force_N, arrival_time_s, tau_s):
        point = (peak_force_N, arrival_time_s, tau_s)
        if point != self._point:
            phase = (time - arrival_time_s) / tau_s
            cosine = np.cos(phase)
            self._parts = (phase, cosine, cosine**6)
            self._point = point
        return self._parts

    def model(self, time_s, peak_force_N, arrival_time_s, tau_s):
        """F_m cos^6((t - T)/tau), N (as :func:`cos6_model`; ``time_s`` an array, s)."""
        return peak_force_N * self._phase_parts(time_s, peak_force_N, arrival_time_s, tau_s)[2]

    def jacobian(self, time_s, peak_force_N, arrival_time_s, tau_s):
        """d model / d(F_m, T, tau), one row per parameter (1, N/s, N/s)."""
        phase, cosine, cos6 = self._phase_parts(time_s, peak_force_N, arrival_time_s, tau_s)
        slope = 6.0 * peak_force_N * cosine**5 * np.sin(phase)  # = -dF/dphase
        rows = np.empty((3, len(phase)))
        rows[0] = cos6
        np.divide(slope, tau_s, out=rows[1])
        np.multiply(slope, phase, out=rows[2])
        rows[2] /= tau_s
        return rows
