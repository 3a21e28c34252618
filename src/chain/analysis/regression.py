"""Least-squares fits with standard errors: y = C x^p (p fixed), y = A x^p (p free),
and y = slope x.

Fixed exponent and proportional fits are linear in their one coefficient and solved in
closed form: with g = x^p and weights w = 1/sigma^2 (w = 1 when no sigma is given),

    C = sum(w g y) / sum(w g^2),   var(C) = s^2 / sum(w g^2),

where s^2 = sum(w (y - C g)^2) / (n - 1) is the reduced chi-square (the residual
variance when unweighted). Scaling by s^2 makes the standard error describe the scatter
actually present, as ``scipy.optimize.curve_fit`` does by default
(``absolute_sigma=False``); with ``absolute_sigma=True`` the given sigma are taken as
the true errors and var(C) = 1 / sum(w g^2).

The free power law is fitted in log-log (default): ln y = ln A + p ln x by
:func:`line_fit` (the arithmetic of :func:`scipy.stats.linregress`, whose import costs
a job a second), right for a relative scatter; or with
``method="nonlinear"`` by ``scipy.optimize.curve_fit`` of A x^p on y itself, right for a
constant absolute scatter. Both give the standard error of p from the residuals.

A fit with too few points (fewer than 2 for one coefficient, 3 for two) returns NaN
values and its ``n_points`` rather than raising, so that tables can hold the row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from chain.errors import ParameterError

#: Fewest points for a one-coefficient fit (one degree of freedom left for its error).
MIN_POINTS_ONE_PARAMETER = 2

#: Fewest points for a two-parameter fit.
MIN_POINTS_TWO_PARAMETERS = 3

POWER_LAW_METHODS = ("loglog", "nonlinear")


@dataclass(frozen=True)
class CoefficientFit:
    """y = coefficient x^exponent with the exponent fixed.

    Attributes
    ----------
    coefficient : float
        C (or the slope), in units of y / x^exponent.
    stderr : float
        Its standard error, same units.
    exponent : float
        The fixed exponent.
    n_points : int
        Points used.
    rms_residual : float
        Root-mean-square of y - C x^p, units of y.
    """

    coefficient: float
    stderr: float
    exponent: float
    n_points: int
    rms_residual: float


@dataclass(frozen=True)
class PowerLawFit:
    """y = prefactor x^exponent with both free.

    Attributes
    ----------
    prefactor, prefactor_stderr : float
        A and its standard error, units of y / x^exponent.
    exponent, exponent_stderr : float
        p and its standard error.
    n_points : int
        Points used.
    method : str
        ``loglog`` or ``nonlinear``.
    """

    prefactor: float
    prefactor_stderr: float
    exponent: float
    exponent_stderr: float
    n_points: int
    method: str


def fit_fixed_exponent(
    x, y, exponent: float = -1.0 / 6.0, sigma=None, *, absolute_sigma: bool = False
) -> CoefficientFit:
    """Least-squares C of y = C x^exponent with its standard error (NaN with fewer
    than 2 points).

    Parameters
    ----------
    x : array
        Abscissae (e.g. F_m in N), > 0.
    y : array
        Ordinates (e.g. |Delta| in us).
    exponent : float
        The fixed exponent (default -1/6, Eq. 6).
    sigma : array, optional
        Standard errors of y, same units; None for unweighted least squares.
    absolute_sigma : bool
        Take ``sigma`` as absolute (True) or only relative (False, the error is then
        scaled by the reduced chi-square).
    """
    x, y, weight = _points(x, y, sigma)
    n = x.size
    if n < MIN_POINTS_ONE_PARAMETER:
        return CoefficientFit(math.nan, math.nan, float(exponent), n, math.nan)
    if np.any(x <= 0):
        raise ParameterError("x must be > 0 for a power law")
    return _coefficient_fit(x**exponent, y, weight, exponent, sigma is not None and absolute_sigma)


def fit_proportional(x, y, sigma=None) -> CoefficientFit:
    """Least-squares slope of y = slope x (through the origin) with its standard error.

    Parameters
    ----------
    x, y : array
        Abscissae and ordinates (e.g. F_m and the SSW amplitude, both in N).
    sigma : array, optional
        Standard errors of y, relative (the error is scaled by the reduced chi-square);
        None for unweighted least squares.
    """
    x, y, weight = _points(x, y, sigma)
    n = x.size
    if n < MIN_POINTS_ONE_PARAMETER:
        return CoefficientFit(math.nan, math.nan, 1.0, n, math.nan)
    return _coefficient_fit(x, y, weight, 1.0, absolute=False)


def _coefficient_fit(basis, y, weight, exponent: float, absolute: bool) -> CoefficientFit:
    """The weighted least-squares C of y = C basis, its error (from the weights alone
    when ``absolute``, else scaled by the reduced chi-square: module docstring)."""
    normal = float(np.sum(weight * basis**2))
    coefficient = float(np.sum(weight * basis * y)) / normal
    residual = y - coefficient * basis
    if absolute:
        variance = 1.0 / normal
    else:
        variance = float(np.sum(weight * residual**2)) / (basis.size - 1) / normal
    rms = float(np.sqrt(np.mean(residual**2)))
    return CoefficientFit(coefficient, math.sqrt(variance), float(exponent), basis.size, rms)


def fit_power_law(x, y, *, method: str = "loglog") -> PowerLawFit:
    """Unweighted least-squares y = A x^p with A and p free, and their standard errors
    (NaN with fewer than 3 points).

    Parameters
    ----------
    x, y : array
        Abscissae and ordinates, both > 0 (use |Delta| for delays).
    method : {"loglog", "nonlinear"}
        Straight line in ln y vs ln x, or nonlinear fit of y (module docstring).
    """
    if method not in POWER_LAW_METHODS:
        raise ParameterError(f"method must be one of {POWER_LAW_METHODS}, got {method!r}")
    x, y, _ = _points(x, y, None)
    n = x.size
    if n < MIN_POINTS_TWO_PARAMETERS:
        return PowerLawFit(math.nan, math.nan, math.nan, math.nan, n, method)
    if np.any(x <= 0) or np.any(y <= 0):
        raise ParameterError("x and y must be > 0 for a power-law fit")
    log_x, log_y = np.log(x), np.log(y)
    if method == "loglog":
        exponent, log_a, exponent_error, log_a_error = line_fit(log_x, log_y)
        prefactor = math.exp(log_a)
        return PowerLawFit(
            prefactor,
            prefactor * float(log_a_error),
            float(exponent),
            float(exponent_error),
            n,
            method,
        )
    from scipy.optimize import curve_fit  # imported here: most fits need no scipy

    start = fit_power_law(x, y, method="loglog")
    params, covariance = curve_fit(
        lambda u, a, p: a * u**p, x, y, p0=(start.prefactor, start.exponent)
    )
    errors = np.sqrt(np.diag(covariance))
    return PowerLawFit(
        float(params[0]), float(errors[0]), float(params[1]), float(errors[1]), n, method
    )


def line_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float, float]:
    """Unweighted least-squares line y = slope x + intercept: (slope, intercept, stderr
    of the slope, stderr of the intercept).

    The arithmetic of :func:`scipy.stats.linregress` (scipy 1.17), operation for
    operation, so that the numbers are the same to the last bit (a test compares them),
    without importing scipy.stats, which costs a job about a second.

    Parameters
    ----------
    x, y : array
        At least 3 points, x not all equal; units of y per unit of x for the slope.
    """
    if np.amax(x) == np.amin(x):
        raise ParameterError("cannot fit a line if all x values are identical")
    x_mean = np.mean(x, None)
    y_mean = np.mean(y, None)
    ssxm, ssxym, _, ssym = np.cov(x, y, bias=1).flat
    if ssxm == 0.0 or ssym == 0.0:
        r = np.asarray(np.nan if ssxym == 0 else 0.0)[()]
    else:
        r = min(max(ssxym / np.sqrt(ssxm * ssym), -1.0), 1.0)
    slope = ssxym / ssxm
    intercept = y_mean - slope * x_mean
    slope_stderr = np.sqrt((1 - r**2) * ssym / ssxm / (len(x) - 2))
    intercept_stderr = slope_stderr * np.sqrt(ssxm + x_mean**2)
    return slope, intercept, slope_stderr, intercept_stderr


def _points(x, y, sigma):
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.shape != y.shape:
        raise ParameterError(f"x and y must have one length, got {x.size} and {y.size}")
    if sigma is None:
        weight = np.ones_like(y)
    else:
        sigma = np.asarray(sigma, dtype=float).ravel()
        if sigma.shape != y.shape:
            raise ParameterError(f"sigma must have {y.size} entries, got {sigma.size}")
        if np.any(~np.isfinite(sigma)) or np.any(sigma <= 0):
            raise ParameterError("sigma must be finite and > 0")
        weight = sigma**-2
    if np.any(~np.isfinite(x)) or np.any(~np.isfinite(y)):
        raise ParameterError("x and y must be finite; drop flagged points before fitting")
    return x, y, weight


def ratio_with_error(top: float, top_err: float, bottom: float, bottom_err: float) -> dict:
    """top / bottom and its error, the relative errors added in quadrature.

    Parameters
    ----------
    top, top_err, bottom, bottom_err : float
        The two numbers and their errors (same units each).

    Returns
    -------
    dict
        ``ratio`` and ``ratio_err`` (NaN where ``bottom`` is 0 or NaN).
    """
    top, top_err, bottom, bottom_err = map(float, (top, top_err, bottom, bottom_err))
    if not bottom or not math.isfinite(bottom):
        return {"ratio": math.nan, "ratio_err": math.nan}
    ratio = top / bottom
    relative = math.hypot(top_err / top if top else math.nan, bottom_err / bottom)
    return {"ratio": ratio, "ratio_err": abs(ratio) * relative}
