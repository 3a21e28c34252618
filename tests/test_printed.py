"""chain.report.printed.plus_minus: the one rule for "value ± error" (article, summary.md,
figure labels). The error keeps 1-2 significant figures, the value the same decimal."""

from __future__ import annotations

import math
import re

import pytest
from hypothesis import given
from hypothesis import strategies as st

from chain.report.printed import error_decimals, plus_minus


@pytest.mark.parametrize(
    ("value", "error", "expected"),
    [
        (43.21, 0.0523, "43.21 ± 0.05"),  # leading digits 52: one significant figure
        (-0.2140, 0.011, "\u22120.214 ± 0.011"),  # 11: two, and the minus sign U+2212
        (49.75, 0.0996, "49.75 ± 0.10"),  # 99.6 rounds up to 10: two figures
        (0.5, 3.2, "0.5 ± 3.2"),  # an error larger than the value keeps the value
        (0.0, 0.05, "0.00 ± 0.05"),
        (1234.5, 56, "1230 ± 60"),  # errors of tens round the value to tens
        (0.0002988, 3.487e-06, "(2.988 ± 0.035) × 10^\u22124"),  # a common power of ten
        (123456.7, 2345.6, "(1.235 ± 0.023) × 10^5"),
        (-3e-9, 4e-11, "(\u22123.00 ± 0.04) × 10^\u22129"),
    ],
)
def test_rounding_rules(value, error, expected):
    assert plus_minus(value, error) == expected


def test_missing_values_and_errors():
    assert plus_minus(None, 0.1) == "n/a"
    assert plus_minus(math.nan, 0.1) == "n/a"
    assert plus_minus(1.5, None) == "1.500"  # 4 significant figures by default
    assert plus_minus(1.5, math.nan, 2) == "1.50"  # the caller's decimals
    assert plus_minus(1.5, 0.0) == "1.500 ± 0"  # an exact value says so
    assert plus_minus(4.5e-6, None) == "4.500 × 10^\u22126"


def test_power_styles():
    assert plus_minus(0.0002988, 3.487e-06, style="unicode") == "(2.988 ± 0.035) × 10⁻⁴"
    assert plus_minus(0.0002988, 3.487e-06, style="mathtext") == (
        r"(2.988 ± 0.035) $\times 10^{-4}$"
    )


def _parse(text: str) -> tuple[float, float, str, str]:
    """value, error and their printed digits of ``(a ± b) × 10^e`` or ``a ± b``."""
    match = re.fullmatch(r"\(?(\S+) ± (\S+?)\)?(?: × 10\^(\S+))?", text)
    assert match, text
    a, b, e = (g.replace("\u2212", "-") if g else g for g in match.groups())
    scale = 10.0 ** int(e) if e else 1.0
    return float(a) * scale, float(b) * scale, a, b


@given(
    value=st.floats(-1e9, 1e9, allow_nan=False),
    error=st.floats(1e-12, 1e9, allow_nan=False),
)
def test_error_has_one_or_two_figures_and_the_value_its_decimal(value, error):
    printed_value, printed_error, a, b = _parse(plus_minus(value, error))
    # Significant figures: from the error's first digit to the last place printed.
    figures = math.floor(math.log10(printed_error)) + error_decimals(error) + 1
    assert figures in (1, 2), b
    # The same decimal: equal counts of digits after the point.
    assert len(a.partition(".")[2]) == len(b.partition(".")[2])
    # Rounding moved the error by under 16 % (the 1-2 figure rule) and the value by
    # under half the printed error's last digit (plus float noise).
    assert abs(printed_error - error) <= 0.16 * error
    last = 10.0 ** -error_decimals(error)
    assert abs(printed_value - value) <= 0.5 * last + 1e-9 * abs(value)


def test_value_with_a_statistical_and_a_systematic_error():
    """Decimals set by the total error; an error below the last decimal says so."""
    from chain.report.printed import plus_minus_stat_sys

    assert plus_minus_stat_sys(5.0, 0.01, 0.20) == "5.00 ± 0.01 (stat) ± 0.20 (sys)"
    assert plus_minus_stat_sys(3.43, 0.003, 2.07) == "3.4 ± < 0.1 (stat) ± 2.1 (sys)"
    assert plus_minus_stat_sys(-1.81, 0.10, 1.61) == "\u22121.8 ± 0.1 (stat) ± 1.6 (sys)"
    assert plus_minus_stat_sys(float("nan"), 0.1, 0.1) == "n/a"
    assert plus_minus_stat_sys(2.5, None, None) == plus_minus(2.5, None)
