"""chain.analysis.peaks and smoothing.savgol_coeffs against scipy.signal, bit for bit:
the analysis finds and measures pulses without importing scipy.signal, and every table
must keep its bytes."""

import numpy as np
import pytest
import scipy.signal
from hypothesis import given, settings
from hypothesis import strategies as st

from chain.analysis.peaks import find_peaks, peak_width
from chain.analysis.smoothing import savgol_coeffs


def assert_same_peaks(signal, **rules):
    expected, expected_properties = scipy.signal.find_peaks(signal, **rules)
    peaks, properties = find_peaks(signal, **rules)
    np.testing.assert_array_equal(peaks, expected)
    for name in (
        ("prominences", "left_bases", "right_bases")
        if expected_properties.get("prominences") is not None
        else ()
    ):
        assert properties[name].tobytes() == expected_properties[name].tobytes(), name
    widths = scipy.signal.peak_widths(signal, expected, rel_height=0.5)[0]
    assert np.array([peak_width(signal, p) for p in peaks]).tobytes() == widths.tobytes()


@settings(max_examples=400, deadline=None)
@given(
    st.lists(st.integers(0, 6), min_size=1, max_size=60),
    st.one_of(st.none(), st.floats(0.0, 3.5)),
    st.one_of(st.none(), st.floats(1.0, 9.0)),
    st.one_of(st.none(), st.floats(0.0, 3.0)),
)
def test_peaks_of_plateaus_and_ties_are_scipys(levels, height, distance, prominence):
    # Small integer levels: plateaus, equal neighbours, equal bases and ties of height.
    signal = np.asarray(levels, dtype=float) * 0.5
    assert_same_peaks(signal, height=height, distance=distance, prominence=prominence)


@pytest.mark.parametrize("seed", range(6))
def test_peaks_of_noisy_quantised_pulses_are_scipys(seed):
    # Two cos^6 pulses (the crossed and incident waves at a sensor) on noise, quantised as
    # a digitiser records them: the rules find_pulses gives find_peaks.
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, 1500)
    waves = ((40.0, 0.3), (rng.uniform(5, 40), rng.uniform(0.45, 0.9)))  # (N, s)
    pulses = sum(a * np.cos(np.clip((t - c) / 0.03, -np.pi / 2, np.pi / 2)) ** 6 for a, c in waves)
    signal = np.round((pulses + rng.normal(0.0, 0.4, t.size)) / 0.05) * 0.05
    largest = signal.max()
    fwhm = scipy.signal.peak_widths(signal, [int(np.argmax(signal))], rel_height=0.5)[0][0]
    assert peak_width(signal, int(np.argmax(signal))) == fwhm
    assert_same_peaks(signal, height=2.0, prominence=0.1 * largest, distance=max(1.0, fwhm))
    assert_same_peaks(signal, prominence=0.02 * largest)


@pytest.mark.parametrize("use", ["conv", "dot"])
@pytest.mark.parametrize("delta", [1.0, 2.5e-7, 0.37])
def test_savgol_coefficients_are_scipys(use, delta):
    for length in range(3, 203, 2):
        for deriv in (0, 1, 2):
            expected = scipy.signal.savgol_coeffs(length, 2, deriv=deriv, delta=delta, use=use)
            got = savgol_coeffs(length, deriv=deriv, delta=delta, use=use)
            assert got.tobytes() == expected.tobytes(), (length, deriv)
