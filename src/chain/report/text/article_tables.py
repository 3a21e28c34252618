"""The article's tables of the C-sensitivity grid and of the ablation, written for reading.

Each table is ``{"columns", "rows"}`` of printed cells: chosen columns, units in the
header, value ± error by :func:`chain.report.printed.plus_minus`. The body of the article
gets the pooled rows (one per choice or variant); the appendix every row. The complete
CSVs (``tables/c_sensitivity.csv``, ``tables/ablation_exponent.csv``) stay the data.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from chain.report.printed import plus_minus

#: Header of C with its unit, as typst prints it (``^`` set as a superscript).
C_HEADER = "C (µs N^1/6)"
EXPONENT_HEADER = "free exponent p"

#: How a choice of the C-sensitivity grid is named in the article.
_CHOICE_NAMES = {
    "estimator": "estimator {value}",
    "eta_us": "η = {value} µs",
    "sensors": "sensors {value}",
    "amplitudes": "amplitudes: {value}",
}


def choice_name(row: Mapping) -> str:
    """'estimator fit_rise', 'η = 1.16 µs', 'sensors shift −2 beads', with ' (headline)'
    for the headline choice."""
    template = _CHOICE_NAMES.get(str(row.get("choice")), "{choice} {value}")
    name = template.format(choice=row.get("choice"), value=row.get("value"))
    return name.replace("-", "\u2212") + (" (headline)" if row.get("headline") else "")


def _fit_cells(row: Mapping) -> list[str]:
    """C ± stderr, p ± stderr and the number of points of one fit row ("—" for a fit
    that was not possible)."""
    cells = [
        plus_minus(row.get("C"), row.get("C_stderr")),
        plus_minus(row.get("exponent"), row.get("exponent_stderr")),
    ]
    return [c.replace("n/a", "—") for c in cells] + [str(row.get("n_points", ""))]


def _with_note(row: Mapping) -> str:
    """The choice's name, with its note (a chain missing from the pooled fit)."""
    note = row.get("note")
    return f"{choice_name(row)} ({note})" if note else choice_name(row)


def _pooled(rows: Sequence[Mapping]) -> list[Mapping]:
    return [r for r in rows if str(r.get("N")) == "pooled"]


def c_spread_tables(rows: Sequence[Mapping] | None) -> dict | None:
    """``{"body", "appendix"}``: the pooled C and exponent per choice of the
    C-sensitivity grid, and every row (per chain, with its note); None for no rows.

    Parameters
    ----------
    rows : sequence of mapping
        Rows of ``c_sensitivity.csv`` (summary ``c_spread.rows``): choice, value, N, C
        and C_stderr (µs N^(1/6)), exponent, exponent_stderr, n_points, headline, note.
    """
    if not rows:
        return None
    body = [[_with_note(r), *_fit_cells(r)] for r in _pooled(rows)]
    appendix = [
        [choice_name(r), str(r.get("N")), *_fit_cells(r), r.get("note") or ""] for r in rows
    ]
    return {
        "body": {"columns": ["Choice", C_HEADER, EXPONENT_HEADER, "points"], "rows": body},
        "appendix": {
            "columns": ["Choice", "N", C_HEADER, EXPONENT_HEADER, "points", "note"],
            "rows": appendix,
        },
    }


def _switched_off(row: Mapping) -> str:
    """The ablation's overrides, one per line: 'noise_N = 0.0'."""
    overrides = str(row.get("overrides") or "")
    return "; ".join(part.strip().replace("=", " = ") for part in overrides.split(";"))


def _variant(row: Mapping) -> str:
    return str(row.get("variant", "")).replace("_", " ")


def ablation_tables(rows: Sequence[Mapping] | None) -> dict | None:
    """``{"body", "appendix"}``: the pooled C and exponent of the virtual experiment per
    ablation variant with what it switches off, and every variant per chain; None for
    no rows.

    Parameters
    ----------
    rows : sequence of mapping
        Rows of ``ablation_exponent.csv`` (summary ``ablation.rows``): variant, N, C and
        C_stderr (µs N^(1/6)), exponent, exponent_stderr, n_points, overrides.
    """
    if not rows:
        return None
    body = [[_variant(r), _switched_off(r), *_fit_cells(r)] for r in _pooled(rows)]
    appendix = [[_variant(r), str(r.get("N")), *_fit_cells(r)] for r in rows]
    return {
        "body": {
            "columns": ["Variant", "switched off", C_HEADER, EXPONENT_HEADER, "points"],
            "rows": body,
        },
        "appendix": {
            "columns": ["Variant", "N", C_HEADER, EXPONENT_HEADER, "points"],
            "rows": appendix,
        },
    }
