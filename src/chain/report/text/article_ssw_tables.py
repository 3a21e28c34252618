"""The article's SSW tables, written for reading: resolution at the sensors, separation
along the chain, and the even / odd ratios at the sensors and far from the collision.

Each table is ``{"columns", "rows"}`` of printed cells, like
:mod:`chain.report.text.article_tables`: a "Series" column named as the rest of the article
names it, chosen columns with units, value ± error by
:func:`chain.report.printed.plus_minus`. The summary keys they read are those of
:func:`chain.report.numbers.summary.ssw_summary`; the CSVs stay the data.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from chain.report.printed import fixed, plus_minus

#: (source, model) -> the series' name in the article.
Labeller = Callable[[str, str], str]

#: Cell of a number this run could not form.
MISSING = "—"

#: Columns of :func:`separation_table`.
SEPARATION_COLUMNS = [
    "Series", "N", "wave", "shots separated", "first contact", "distance (beads)",
    "speed / Eq. 5",
]  # fmt: skip


def _count(done, total) -> str:
    return f"{int(done)} of {int(total)}"


def _shots(row: Mapping) -> str:
    if row.get("n_shots") is None:
        return MISSING
    return _count(row.get("n_shots_separated", 0), row["n_shots"])


def _number(value, decimals: int) -> str:
    text = fixed(value, decimals)
    return MISSING if text == "n/a" else text


def resolution_table(rows: Sequence[Mapping] | None, label: Labeller) -> dict | None:
    """Collision shots whose SSW is resolved as a separate wave, per series, chain and
    sensor (summary ``ssw_resolved``); None for no rows."""
    if not rows:
        return None
    cells: dict[tuple, dict] = {}
    for row in rows:
        key = (label(row["source"], row["model"]), int(row["N"]))
        cells.setdefault(key, {})[row["sensor"]] = _count(row["n_resolved"], row["n_total"])
    return {
        "columns": ["Series", "N", "S1 (RSTW)", "S2 (LSTW)"],
        "rows": [
            [name, str(n), found.get("S1", MISSING), found.get("S2", MISSING)]
            for (name, n), found in cells.items()
        ],
    }


def separation_table(rows: Sequence[Mapping] | None, label: Labeller) -> dict | None:
    """Where the SSW separates along the chain and its speed over Eq. 5's for its own
    amplitude (summary ``ssw_separation``); None for no rows."""
    if not rows:
        return None
    return {
        "columns": SEPARATION_COLUMNS,
        "rows": [
            [
                label(row.get("source", "simulation"), row["model"]),
                str(row["N"]),
                str(row["wave"]),
                _shots(row),
                _number(row.get("first_separated_contact"), 0),
                _number(row.get("distance_beads"), 1),
                _number(row.get("speed_ratio"), 3),
            ]
            for row in rows
        ],
    }


def parity_table(rows: Sequence[Mapping] | None, label: Labeller) -> dict | None:
    """SSW slope of the even chain over the odd one's at the sensors, ± its error
    (summary ``ssw_parity_ratio``); None for no rows."""
    if not rows:
        return None
    return {
        "columns": ["Series", "SSW slope N = 26 / N = 25"],
        "rows": [
            [label(row["source"], row["model"]), plus_minus(row["ratio"], row.get("ratio_err"))]
            for row in rows
        ],
    }


def far_field_table(rows: Sequence[Mapping] | None, label: Labeller) -> dict | None:
    """SSW / F_m of the long even and odd chains far from the collision point and their
    ratio (summary ``ssw_far_field``); None for no rows."""
    if not rows:
        return None
    return {
        "columns": ["Series", "chains", "even: SSW/F_m (%)", "odd: SSW/F_m (%)", "even / odd"],
        "rows": [
            [
                label(row["source"], row["model"]),
                f"N = {row['even_N']} / {row['odd_N']}",
                plus_minus(100 * row["even"], 100 * row["even_err"]),
                plus_minus(100 * row["odd"], 100 * row["odd_err"]),
                plus_minus(row["ratio"], row["ratio_err"]),
            ]
            for row in rows
        ],
    }
