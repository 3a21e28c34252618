"""Power-law and proportional fits: recovery of synthetic truths and honest errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chain.analysis.regression import (
    fit_fixed_exponent,
    fit_power_law,
    fit_proportional,
    line_fit,
    ratio_with_error,
)

# Delta = C F_m^(-1/6) over the paper's range of forces.
C_TRUE = 45.9  # us N^(1/6)
EXPONENT_TRUE = -1.0 / 6.0
FORCES_N = np.geomspace(10.0, 1000.0, 20)
NOISE_US = 0.3  # absolute scatter of Delta, us (about 1 % of it)
N_SEEDS = 200

#: Fraction of seeds where |estimate - truth| <= 1 stderr: 68.3 % for a Gaussian
#: estimate, ~67 % with the t distribution of 18-19 degrees of freedom. Binomial
#: standard deviation over 200 seeds: 3.3 %; allowed: 4 of those.
COVERAGE_EXPECTED = 0.67
COVERAGE_TOLERANCE = 4 * math.sqrt(0.68 * 0.32 / N_SEEDS)

#: Recovery with 1 % noise on 20 points, a few standard errors.
C_RELATIVE_TOLERANCE = 0.01
EXPONENT_TOLERANCE = 0.01


def synthetic_delays(seed: int, relative: bool = False) -> np.ndarray:
    rng = np.random.default_rng(seed)
    clean = C_TRUE * FORCES_N**EXPONENT_TRUE
    if relative:
        return clean * np.exp(rng.normal(0.0, 0.01, FORCES_N.size))
    return clean + rng.normal(0.0, NOISE_US, FORCES_N.size)


def test_exact_data_give_exact_parameters():
    clean = C_TRUE * FORCES_N**EXPONENT_TRUE
    fixed = fit_fixed_exponent(FORCES_N, clean)
    assert fixed.coefficient == pytest.approx(C_TRUE, rel=1e-12)
    assert fixed.stderr == pytest.approx(0.0, abs=1e-9)
    for method in ("loglog", "nonlinear"):
        free = fit_power_law(FORCES_N, clean, method=method)
        assert free.exponent == pytest.approx(EXPONENT_TRUE, abs=1e-9)
        assert free.prefactor == pytest.approx(C_TRUE, rel=1e-8)
    assert fit_proportional([1.0, 2.0, 3.0], [0.5, 1.0, 1.5]).coefficient == pytest.approx(0.5)


def test_noisy_data_recover_c_and_exponent():
    delays = synthetic_delays(seed=0)
    fixed = fit_fixed_exponent(FORCES_N, delays)
    free = fit_power_law(FORCES_N, delays)
    assert fixed.n_points == free.n_points == FORCES_N.size
    assert fixed.coefficient == pytest.approx(C_TRUE, rel=C_RELATIVE_TOLERANCE)
    assert free.exponent == pytest.approx(EXPONENT_TRUE, abs=EXPONENT_TOLERANCE)
    assert free.prefactor == pytest.approx(C_TRUE, rel=5 * C_RELATIVE_TOLERANCE)


def _coverage(estimates, errors, truth) -> float:
    return float(np.mean(np.abs(np.asarray(estimates) - truth) <= np.asarray(errors)))


@pytest.mark.parametrize(
    ("method", "relative"),
    [("loglog", False), ("loglog", True), ("nonlinear", False)],
)
def test_standard_errors_cover_the_truth_at_the_expected_rate(method, relative):
    fixed, free = [], []
    for seed in range(N_SEEDS):
        delays = synthetic_delays(seed, relative)
        a = fit_fixed_exponent(FORCES_N, delays)
        b = fit_power_law(FORCES_N, delays, method=method)
        fixed.append((a.coefficient, a.stderr))
        free.append((b.exponent, b.exponent_stderr))
    fixed, free = np.array(fixed), np.array(free)
    for coverage in (
        _coverage(fixed[:, 0], fixed[:, 1], C_TRUE),
        _coverage(free[:, 0], free[:, 1], EXPONENT_TRUE),
    ):
        assert abs(coverage - COVERAGE_EXPECTED) < COVERAGE_TOLERANCE, coverage


def test_weighted_fits_with_absolute_sigma_cover_the_truth():
    sigma = NOISE_US * np.linspace(0.5, 2.0, FORCES_N.size)  # heteroscedastic
    hits = []
    for seed in range(N_SEEDS):
        rng = np.random.default_rng(seed)
        delays = C_TRUE * FORCES_N**EXPONENT_TRUE + rng.normal(0.0, sigma)
        fit = fit_fixed_exponent(FORCES_N, delays, sigma=sigma, absolute_sigma=True)
        hits.append(abs(fit.coefficient - C_TRUE) <= fit.stderr)
    # Known errors: Gaussian, not t, coverage.
    assert abs(np.mean(hits) - 0.683) < COVERAGE_TOLERANCE


def test_proportional_slope_and_error():
    rng = np.random.default_rng(5)
    force = np.geomspace(10.0, 1000.0, 20)
    ssw = 0.04 * force * (1.0 + rng.normal(0.0, 0.02, force.size))
    fit = fit_proportional(force, ssw)
    assert fit.coefficient == pytest.approx(0.04, rel=0.02)
    assert 0 < fit.stderr < 0.01 * 0.04


def test_too_few_points_give_nan_and_a_count():
    fixed = fit_fixed_exponent([100.0], [10.0])
    assert math.isnan(fixed.coefficient) and fixed.n_points == 1
    free = fit_power_law([10.0, 100.0], [20.0, 15.0])
    assert math.isnan(free.exponent) and free.n_points == 2
    assert fit_proportional([], []).n_points == 0


def test_bad_input_raises():
    with pytest.raises(ValueError):
        fit_fixed_exponent([1.0, 2.0], [1.0])
    with pytest.raises(ValueError):
        fit_power_law([1.0, 2.0, 3.0], [1.0, -1.0, 1.0])
    with pytest.raises(ValueError):
        fit_proportional([1.0, np.nan], [1.0, 2.0])


def test_ratio_error_propagates_relative_errors_and_matches_sampling():
    """top / bottom with relative errors in quadrature: 6 ± 0.3 over 2 ± 0.1 is 3 with a
    relative error sqrt(2) x 5 %; a Monte-Carlo draw agrees (small errors: linear regime);
    a zero or NaN denominator gives NaN."""
    found = ratio_with_error(6.0, 0.3, 2.0, 0.1)
    assert found["ratio"] == 3.0
    assert found["ratio_err"] == pytest.approx(3.0 * 0.05 * np.sqrt(2.0))
    rng = np.random.default_rng(1)
    draws = rng.normal(6.0, 0.03, 200_000) / rng.normal(2.0, 0.01, 200_000)
    small = ratio_with_error(6.0, 0.03, 2.0, 0.01)
    assert np.std(draws) == pytest.approx(small["ratio_err"], rel=0.01)
    assert np.isnan(ratio_with_error(1.0, 0.1, 0.0, 0.1)["ratio"])
    assert np.isnan(ratio_with_error(1.0, 0.1, float("nan"), 0.1)["ratio_err"])


@pytest.mark.parametrize("seed", range(40))
def test_line_fit_is_scipy_linregress_to_the_bit(seed):
    """line_fit replaces scipy.stats.linregress (a second of import per job) in the
    log-log fits: the same four numbers, bit for bit, so that no table changes."""
    from scipy.stats import linregress

    rng = np.random.default_rng(seed)
    n = int(rng.integers(3, 40))
    x = np.log(np.sort(rng.uniform(5.0, 2000.0, n)))
    y = rng.normal(-1.0 / 6.0, 10.0 ** rng.uniform(-6, 0)) * x + rng.normal(0.0, 0.05, n)
    if seed == 0:
        y = 3.0 - x / 6.0  # exact line: r clipped to -1, zero stderr
    if seed == 1:
        y = np.full(n, 2.0)  # flat: r undefined
    expected = linregress(x, y)
    got = line_fit(x, y)
    want = (expected.slope, expected.intercept, expected.stderr, expected.intercept_stderr)
    np.testing.assert_array_equal(np.array(got), np.array(want))


def test_line_fit_refuses_equal_x():
    with pytest.raises(ValueError, match="identical"):
        line_fit(np.ones(4), np.arange(4.0))
