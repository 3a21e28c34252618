"""Row hygiene of results tables: which rows a figure or a fit may use.

A flagged row (``ok`` False, with its ``reason``) or a NaN never passes quietly
into a figure or a fit; how many were left out, and why, goes to the log.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable

import numpy as np
import pandas as pd

log = logging.getLogger(__name__)


def is_ok(table: pd.DataFrame, column: str = "ok") -> pd.Series:
    """A flag column (``ok``, ``kept``) as booleans, however the table was read.

    True/False or their text ("true", "1") count; a missing column is all True, a
    missing or NaN value is False. The one reading of a flag column in the library.

    Parameters
    ----------
    table : DataFrame
        A results table.
    column : str
        Name of the flag column.
    """
    if column not in table.columns:
        return pd.Series(True, index=table.index)
    values = table[column]
    if values.dtype == bool:
        return values
    return values.astype(str).str.strip().str.lower().isin(("true", "1", "1.0"))


def usable_rows(
    table: pd.DataFrame, columns: Iterable[str], what: str = "rows", *, positive: bool = False
) -> pd.DataFrame:
    """The rows fit to draw or fit: ``ok`` True and finite (and > 0 if ``positive``) in
    ``columns``; how many were left out, and why, goes to the log (INFO).

    Parameters
    ----------
    table : DataFrame
        A results table with an ``ok`` column (``delays.csv``, ``ssw.csv``, ...).
    columns : iterable of str
        Value columns that must be finite.
    what : str
        Name of the rows in the log message.
    positive : bool
        Also require values > 0 (for a log axis).
    """
    columns = list(columns)
    ok = is_ok(table)
    values = table[columns].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)
    finite = np.isfinite(values).all(axis=1) if columns else np.ones(len(table), bool)
    good = ok.to_numpy() & finite
    nonpositive = np.zeros(len(table), bool)
    if positive and columns:
        nonpositive = good & ~(values > 0).all(axis=1)
        good &= ~nonpositive
    left_out = len(table) - int(good.sum())
    if left_out:
        log.info(
            "%s: %d of %d left out (%d flagged ok = False, %d ok but NaN/inf in %s%s)",
            what,
            left_out,
            len(table),
            int((~ok).sum()),
            int((ok.to_numpy() & ~finite).sum()),
            columns,
            f", {int(nonpositive.sum())} <= 0 on a log axis" if positive else "",
        )
    return table[good]


def flag_unusable(
    table: pd.DataFrame, columns: Iterable[str], what: str = "rows", where=None
) -> pd.DataFrame:
    """``table`` with ``ok`` set False on the rows :func:`usable_rows` leaves out (the
    count goes to the log), among the rows selected by the boolean mask ``where``.

    The fits (``delay_fit_table``, ``ssw_fit_table``) refuse a NaN in an ``ok`` row;
    this is the row policy a pipeline applies before them.

    Parameters
    ----------
    table : DataFrame
        A results table.
    columns : iterable of str
        Value columns that must be finite.
    what : str
        Name of the rows in the log message.
    where : array of bool, optional
        Rows the policy applies to (default: all); the others are returned unchanged.
    """
    where = np.ones(len(table), bool) if where is None else np.asarray(where, bool)
    usable = usable_rows(table[where], columns, what)
    table = table.copy()
    table.loc[where, "ok"] = table.index[where].isin(usable.index)
    return table


def flag_counts(table: pd.DataFrame | None, columns: Iterable[str] = ()) -> dict:
    """Rows and flagged rows of a results table, per source: ``{source: {"rows": n,
    "flagged": n_ok_false, "nan": n_ok_but_nan}}``.

    Parameters
    ----------
    table : DataFrame or None
        A table with ``source`` and ``ok`` columns.
    columns : iterable of str
        Value columns: an ``ok`` row with a NaN there counts as ``nan``.
    """
    if table is None or not len(table):
        return {}
    columns = list(columns)
    ok = is_ok(table)
    counts = {}
    for source, group in table.groupby("source", sort=True):
        good = ok.loc[group.index]
        values = group[columns].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)
        nan = good.to_numpy() & ~np.isfinite(values).all(axis=1) if columns else 0
        counts[str(source)] = {
            "rows": len(group),
            "flagged": int((~good).sum()),
            "nan": int(np.sum(nan)),
        }
    return counts


def of_estimator(table: pd.DataFrame, estimator: str) -> pd.DataFrame:
    """The rows of ``table`` (with an ``estimator`` column) made with pulse estimator
    ``estimator`` (:data:`chain.analysis.pulses.ESTIMATORS`), in their order, indexed
    0..n-1: a study's job fits every estimator of the run, so that a what-if that only
    picks another main estimator reuses the job, and its report takes the main one's."""
    return _tagged(table, "estimator", estimator)


def picked(table: pd.DataFrame, column: str, value: str) -> pd.DataFrame:
    """The rows of ``table`` whose ``column`` is ``value``, in their order, indexed
    0..n-1, without that column: the table a study tagged per estimator would have
    written for that one alone.

    Parameters
    ----------
    table : DataFrame
        Rows tagged in ``column``.
    column : str
        The tag column (e.g. ``estimator``, ``main_estimator``).
    value : str
        The tag of the rows kept.
    """
    return _tagged(table, column, value).drop(columns=column)


def _tagged(table: pd.DataFrame, column: str, value: str) -> pd.DataFrame:
    # The rows whose tag is ``value``, in their order, indexed 0..n-1 (tags compared as
    # text: a table read back from CSV holds what was written).
    if column not in table:
        raise KeyError(f"no {column!r} column to pick {value!r} rows from")
    return table[table[column].astype(str) == str(value)].reset_index(drop=True)
