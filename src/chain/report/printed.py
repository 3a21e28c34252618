"""Numbers as the article, summary.md and the figures print them: fixed decimals, the minus
sign U+2212, value ± standard error (:func:`plus_minus`, the one home of that rule), powers
of ten, and tables of records whose columns are not known here."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence


def minus(text: str) -> str:
    """``text`` with ASCII hyphen-minus signs of numbers as the minus sign U+2212."""
    return text.replace("-", "\u2212")


def fixed(value, decimals: int) -> str:
    """``value`` with ``decimals`` decimals (minus sign U+2212), or ``n/a`` for None/NaN."""
    if value is None or not math.isfinite(float(value)):
        return "n/a"
    return minus(f"{float(value):.{decimals}f}")


#: Exponents of ten beyond which a value ± error is printed with a common power of ten.
POWER_LIMITS = (-3, 5)

#: How a common power of ten is printed: plain text (the article's typst sets ``^``
#: as a superscript), Unicode superscripts (Markdown) and matplotlib mathtext.
POWER_STYLES = {
    "text": "× 10^{exponent}",
    "unicode": "× 10{superscript}",
    "mathtext": r"$\times 10^{{{ascii}}}$",
}

_SUPERSCRIPTS = str.maketrans("0123456789\u2212", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")


def _finite(value) -> bool:
    return value is not None and math.isfinite(float(value))


def error_decimals(error: float) -> int:
    """Decimals that print ``error`` (> 0, finite) to 1 or 2 significant figures: two
    when its leading digits are 10-35, one otherwise (the Particle Data Group rule),
    so that an error is never rounded by more than about 15 % of itself. Negative for
    errors of 10 and more (round to tens, hundreds, ...)."""
    exponent = math.floor(math.log10(error))
    leading = error / 10.0**exponent  # in [1, 10)
    if round(leading, 1) >= 9.95:  # 9.96 -> "10": one more digit before the point
        exponent += 1
        leading = 1.0
    return -exponent + (1 if leading < 3.55 else 0)


def _decimal_text(value: float, decimals: int) -> str:
    """``value`` rounded to ``decimals`` decimals (tens, hundreds... if negative)."""
    if decimals < 0:
        return minus(f"{round(value, decimals):.0f}")
    return minus(f"{value:.{decimals}f}")


def plus_minus(value, error, decimals: int | None = None, style: str = "text") -> str:
    """``value ± error`` as printed in the article, summary.md and the figures.

    The error is rounded to 1-2 significant figures (:func:`error_decimals`) and the
    value to the same decimal. Values and errors far from 1 (power of ten of the larger
    outside :data:`POWER_LIMITS`) share one power of ten: ``(2.988 ± 0.035) × 10^−4``.
    Minus signs are U+2212.

    Parameters
    ----------
    value, error : float or None
        The number and its standard error, in the same unit (any). A value of None or
        NaN prints ``n/a``; an error of None or NaN prints the value alone, an error of
        0 as ``± 0``.
    decimals : int, optional
        Decimals of the value when no error sets them (error None, NaN or 0); default
        4 significant figures.
    style : {"text", "unicode", "mathtext"}
        How a common power of ten is written (:data:`POWER_STYLES`).
    """
    if not _finite(value):
        return "n/a"
    value = float(value)
    has_error = _finite(error) and float(error) > 0
    scale = max(abs(value), float(error) if has_error else 0.0)
    exponent = math.floor(math.log10(scale)) if scale > 0 else 0
    if not POWER_LIMITS[0] <= exponent < POWER_LIMITS[1]:
        body = plus_minus(value / 10.0**exponent, _scaled(error, exponent), None, style)
        return _with_power(f"({body})" if "±" in body else body, minus(str(exponent)), style)
    if has_error:
        places = error_decimals(float(error))
        return f"{_decimal_text(value, places)} ± {_decimal_text(float(error), places)}"
    if decimals is None:
        decimals = max(0, 3 - exponent)  # 4 significant figures
    text = _decimal_text(value, decimals)
    return text if not _finite(error) else f"{text} ± 0"


def plus_minus_stat_sys(value, stat, sys) -> str:
    """``value ± stat (stat) ± sys (sys)``: decimals set by the total error
    (:func:`error_decimals` of stat and sys in quadrature), the same for all three; an
    error below the last decimal printed as ``< 0.0…1``. Plain text, no power of ten
    (for values of order 1, such as percentages)."""
    if not _finite(value):
        return "n/a"
    parts = [float(e) if _finite(e) else 0.0 for e in (stat, sys)]
    total = math.hypot(*parts)
    if total <= 0:
        return plus_minus(value, None)
    places = error_decimals(total)

    def part(error: float, name: str) -> str:
        if round(error, places) == 0:
            return f"< {_decimal_text(10.0**-places, places)} ({name})"
        return f"{_decimal_text(error, places)} ({name})"

    value_text = _decimal_text(float(value), places)
    return f"{value_text} ± {part(parts[0], 'stat')} ± {part(parts[1], 'sys')}"


def _scaled(error, exponent: int):
    """``error`` / 10**exponent, None and NaN kept as they are."""
    return float(error) / 10.0**exponent if _finite(error) else error


def scientific(value, significant: int = 2) -> dict | None:
    """``value`` as ``{"mantissa", "exponent"}`` strings (``significant`` digits), printed
    mantissa × 10^exponent; None for None, NaN or 0."""
    if value is None or not math.isfinite(float(value)) or value == 0:
        return None
    mantissa, exponent = f"{float(value):.{significant - 1}e}".split("e")
    return {"mantissa": minus(mantissa), "exponent": minus(str(int(exponent)))}


def power_of_ten(value, significant: int = 2, style: str = "text") -> str:
    """``value`` as a reader writes a very small or large number: ``5.5 × 10^−10``,
    never ``5.5e-10``; ``n/a`` for None or NaN, ``0`` for 0. The one home of that rule
    (:func:`number` uses it where a plain number would need an exponent).

    Parameters
    ----------
    value : float or None
        The number, any unit.
    significant : int
        Significant digits of the mantissa.
    style : {"text", "unicode", "mathtext"}
        How the power of ten is written (:data:`POWER_STYLES`): ``× 10^−10`` for the
        article (its typst source sets ``^`` as a superscript), ``× 10⁻¹⁰`` for
        Markdown, mathtext for figures.
    """
    if not _finite(value):
        return "n/a"
    parts = scientific(value, significant)
    if parts is None:
        return "0"
    return _with_power(parts["mantissa"], parts["exponent"], style)


def _with_power(mantissa: str, exponent: str, style: str) -> str:
    """``mantissa × 10^exponent`` in ``style`` (:data:`POWER_STYLES`); both printed."""
    power = POWER_STYLES[style].format(
        exponent=exponent,
        superscript=exponent.translate(_SUPERSCRIPTS),
        ascii=exponent.replace("\u2212", "-"),
    )
    return f"{mantissa} {power}"


def number(value, significant: int = 4, style: str = "text") -> str:
    """``value`` to ``significant`` digits as ``{:g}`` would print it, minus sign
    U+2212, but with a power of ten (:func:`power_of_ten`) where ``{:g}`` would write
    e-notation; ``n/a`` for None or NaN."""
    if not _finite(value):
        return "n/a"
    text = f"{float(value):.{significant}g}"
    if "e" not in text:
        return minus(text)
    mantissa, exponent = text.split("e")  # the digits {:g} keeps, trailing zeros dropped
    return _with_power(minus(mantissa), minus(str(int(exponent))), style)


#: A number in e-notation inside a text ("5.5e-10", "1e+03"); not part of a word or of a
#: hexadecimal hash such as a commit's.
E_NOTATION = re.compile(r"(?<![\w.])[+\-\u2212]?\d+(?:\.\d+)?[eE][+\-\u2212]?\d+(?![\w.])")


def without_e_notation(text: str, style: str = "text") -> str:
    """``text`` with every number in e-notation (:data:`E_NOTATION`) written with a
    power of ten (:func:`number`, 4 significant digits): for texts made elsewhere, such
    as a study's setting names ("gap_mean_m=1e-07" -> "gap_mean_m=1 × 10^−7")."""
    return E_NOTATION.sub(
        lambda match: number(float(match.group().replace("\u2212", "-")), 4, style), str(text)
    )


def percent(value: float, reference: float, decimals: int = 1) -> str:
    """Signed relative difference of ``value`` from ``reference``, in %."""
    return minus(f"{100.0 * (value / reference - 1.0):+.{decimals}f}") + " %"


def cell(value) -> str:
    """A table cell of a finding whose columns this module does not know."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return number(value, 4)
    return without_e_notation(str(value))


def table_of(rows: Sequence[Mapping] | None) -> dict | None:
    """A list of records as ``{"columns", "rows"}`` of printed cells (columns of the first
    record, in order), or None for none."""
    if not rows:
        return None
    columns = list(rows[0])
    return {
        "columns": columns,
        "rows": [[cell(row.get(column)) for column in columns] for row in rows],
    }
