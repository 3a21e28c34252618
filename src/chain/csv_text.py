"""The CSV text of a table: the bytes pandas writes, formatted a column at a time.

``DataFrame.to_csv`` with a ``float_format`` formats every float through a generic
per-cell path: 1 s for a 5 MB trace table, a quarter of a simulation job. The same
text is built here from whole columns (Python's ``%`` on a list of floats, then one
join per row), 3-5x faster. Tables this module does not handle exactly as pandas
does (text that would need quoting, a single column, dtypes other than float, int,
bool and plain text) are written by pandas itself, so the bytes never depend on
which path wrote them (``tests/test_csv_text.py`` compares the two).
"""

from __future__ import annotations

from collections.abc import Iterator
from itertools import islice

import numpy as np
import pandas as pd

#: CSV float format: 10 significant digits, ample for forces and times, and fixed bytes.
FLOAT_FORMAT = "%.10g"

#: Characters that make pandas (the csv module, QUOTE_MINIMAL) quote a text field.
_QUOTED = (",", '"', "\n", "\r")

#: Rows per chunk of :func:`csv_chunks`.
ROWS_PER_CHUNK = 10_000


def csv_text(table: pd.DataFrame) -> str:
    """``table`` as CSV text: no index, floats as :data:`FLOAT_FORMAT`, ``\\n`` line
    ends, missing values empty; identical to ``table.to_csv(index=False,
    float_format=FLOAT_FORMAT, lineterminator="\\n")``.

    Parameters
    ----------
    table : DataFrame
        Any table; one with values this module does not format is passed to pandas.
    """
    return "".join(csv_chunks(table))


def csv_chunks(table: pd.DataFrame) -> Iterator[str]:
    """:func:`csv_text` in pieces of up to :data:`ROWS_PER_CHUNK` rows (the header first),
    for writing to a file as they come.

    Parameters
    ----------
    table : DataFrame
        Any table.
    """
    names = list(table.columns)
    columns = None
    if len(names) > 1 and all(_plain_text(name) for name in names):
        columns = [_column_text(table.iloc[:, i]) for i in range(len(names))]
    if columns is None or any(column is None for column in columns):
        yield table.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")
        return
    yield ",".join(names) + "\n"
    rows = map(",".join, zip(*columns))
    while chunk := list(islice(rows, ROWS_PER_CHUNK)):
        yield "\n".join(chunk) + "\n"


def _column_text(column: pd.Series) -> list[str] | None:
    """The column's cells as text, or None when pandas would write them differently."""
    dtype = column.dtype
    values = column.to_numpy()
    # numpy dtypes only: pandas' nullable Int64, Float64 and boolean are its own.
    if dtype == np.float64:
        return [FLOAT_FORMAT % x if x == x else "" for x in values.tolist()]
    if isinstance(dtype, np.dtype) and dtype.kind in "iub":
        return list(map(str, values.tolist()))
    if dtype == np.dtype(object) or isinstance(dtype, pd.StringDtype):
        missing = column.isna().to_numpy()
        # Checked once per distinct value: text columns are labels that repeat.
        if all(_plain_text(x) for x in column[~missing].unique()):
            cells = values.tolist()
            for i in np.flatnonzero(missing).tolist():
                cells[i] = ""
            return cells
    return None


def _plain_text(value) -> bool:
    """A string pandas writes as it is (no quoting)."""
    return isinstance(value, str) and not any(c in value for c in _QUOTED)
