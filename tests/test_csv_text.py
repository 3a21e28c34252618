"""chain.csv_text writes the bytes pandas writes, for every kind of table the results
hold and for the ones it hands back to pandas."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chain.atomic import write_csv_atomic
from chain.csv_text import FLOAT_FORMAT, ROWS_PER_CHUNK, csv_chunks, csv_text


def pandas_text(table: pd.DataFrame) -> str:
    return table.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")


EDGE_FLOATS = [0.0, -0.0, 1.0, -2.5, 1e-314, 5e-324, 1.7976931348623157e308, np.inf, -np.inf,
               np.nan, 1 / 3, 123456789.0123, 1e-6, 2e22]  # fmt: skip

TABLES = {
    "trace-like": lambda: pd.DataFrame(
        {
            "source": ["simulation"] * len(EDGE_FLOATS),
            "N": np.arange(len(EDGE_FLOATS), dtype=np.int64),
            "ok": [True, False] * (len(EDGE_FLOATS) // 2),
            "t_s": np.linspace(0, 1e-3, len(EDGE_FLOATS)),
            "force_bead9_N": EDGE_FLOATS,
        }
    ),
    "text with missing values": lambda: pd.DataFrame(
        {"name": ["a", None, "b", np.nan], "x": [1.0, 2.0, np.nan, 4.0]}
    ),
    "pandas string dtype": lambda: pd.DataFrame(
        {"name": pd.array(["a", None, "c"], dtype="string"), "x": [1, 2, 3]}
    ),
    "text that needs quotes": lambda: pd.DataFrame(
        {"note": ["a, b", 'say "x"', "two\nlines"], "x": [1.0, 2.0, 3.0]}
    ),
    "header that needs quotes": lambda: pd.DataFrame({"a,b": [1.0], "c": [2.0]}),
    "one column": lambda: pd.DataFrame({"note": ["", "a"]}),
    "no rows": lambda: pd.DataFrame({"a": pd.Series([], dtype=float), "b": []}),
    "float32": lambda: pd.DataFrame({"a": np.array([0.1, 0.2], dtype=np.float32), "b": [1.0, 2.0]}),
    "nullable ints": lambda: pd.DataFrame(
        {"a": pd.array([17, None], dtype="Int64"), "b": [1.0, 2.0]}
    ),
    "nullable floats and booleans": lambda: pd.DataFrame(
        {"a": pd.array([1.5, None], dtype="Float64"), "b": pd.array([True, None], dtype="boolean")}
    ),
    "floats in an object column": lambda: pd.DataFrame(
        {"a": np.array([17.0, np.nan], dtype=object), "b": [1.0, 2.0]}
    ),
    "mixed object column": lambda: pd.DataFrame({"a": ["x", 1.5, 2], "b": [1, 2, 3]}),
    "categories": lambda: pd.DataFrame({"a": pd.Categorical(["x", "y"]), "b": [0.5, 1.5]}),
}


@pytest.mark.parametrize("name", sorted(TABLES))
def test_same_bytes_as_pandas(name):
    table = TABLES[name]()
    assert csv_text(table) == pandas_text(table)


@pytest.mark.parametrize("name", ["trace-like", "text with missing values", "pandas string dtype"])
def test_tables_of_the_results_are_not_handed_to_pandas(name, monkeypatch):
    table = TABLES[name]()
    expected = pandas_text(table)

    def refuse(*args, **kwargs):
        raise AssertionError("handed to pandas")

    monkeypatch.setattr(pd.DataFrame, "to_csv", refuse)
    assert csv_text(table) == expected


def test_the_fast_path_formats_the_trace_columns():
    text = csv_text(TABLES["trace-like"]())
    assert "1.701785255e-314" not in text and "1e-314" in text
    assert ",-0\n" in text and ",inf\n" in text and ",-inf\n" in text and ",\n" in text


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=1, max_size=40),
    st.lists(st.integers(-(2**62), 2**62), min_size=1, max_size=40),
    st.lists(st.text(alphabet="abc ,\"'\n_-.xyz", max_size=6), min_size=1, max_size=40),
)
def test_random_tables_give_pandas_bytes(floats, ints, texts):
    n = min(len(floats), len(ints), len(texts))
    table = pd.DataFrame({"x": floats[:n], "i": ints[:n], "label": texts[:n]})
    assert csv_text(table) == pandas_text(table)


def test_write_csv_atomic_writes_the_text(tmp_path):
    table = TABLES["trace-like"]()
    write_csv_atomic(table, tmp_path / "t.csv")
    assert (tmp_path / "t.csv").read_bytes() == pandas_text(table).encode()


def test_chunks_of_a_long_table_join_to_pandas_bytes():
    rows = 2 * ROWS_PER_CHUNK + 1
    table = pd.DataFrame({"shot": np.arange(rows) % 7, "t_s": np.arange(rows) * 1e-6})
    chunks = list(csv_chunks(table))
    assert len(chunks) == 4  # the header, then three pieces of rows
    assert "".join(chunks) == pandas_text(table)
