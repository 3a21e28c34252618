"""Numbers as the article prints them: fixed decimals, the minus sign U+2212, value ±
standard error, powers of ten, and tables of records whose columns are not known here."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence


def minus(text: str) -> str:
    """``text`` with ASCII hyphen-minus signs of numbers as the minus sign U+2212."""
    return text.replace("-", "\u2212")


def fixed(value, decimals: int) -> str:
    """``value`` with ``decimals`` decimals (minus sign U+2212), or ``n/a`` for None/NaN."""
    if value is None or not math.isfinite(float(value)):
        return "n/a"
    return minus(f"{float(value):.{decimals}f}")


def plus_minus(value, error, decimals: int) -> str:
    """``value ± error``, both with ``decimals`` decimals; an error below the last digit
    printed as ``< 0.0…1``."""
    text = fixed(value, decimals)
    if error is None or text == "n/a" or not math.isfinite(float(error)):
        return text
    if round(float(error), decimals) == 0:
        return f"{text} ± < {10.0**-decimals:.{decimals}f}"
    return f"{text} ± {float(error):.{decimals}f}"


def scientific(value, significant: int = 2) -> dict | None:
    """``value`` as ``{"mantissa", "exponent"}`` strings (``significant`` digits), printed
    mantissa × 10^exponent; None for None, NaN or 0."""
    if value is None or not math.isfinite(float(value)) or value == 0:
        return None
    mantissa, exponent = f"{float(value):.{significant - 1}e}".split("e")
    return {"mantissa": minus(mantissa), "exponent": minus(str(int(exponent)))}


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
        return "n/a" if not math.isfinite(value) else minus(f"{value:.4g}")
    return str(value)


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
