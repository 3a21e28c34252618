"""The one trace format: write/read round trip and validation errors that say where."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from chain import (
    TraceFormatError,
    read_traces,
    simulate,
    uniform_chain,
    validate_traces,
    write_traces,
)
from chain.apparatus.shots import trace_table
from chain.traces import META_COLUMNS, iter_shots, sensor_beads, sensor_column


@pytest.fixture
def traces() -> pd.DataFrame:
    """Two shots (a collision and a reference) of 50 samples at 1 MHz, sensors at beads
    10 and 17 of N = 26, forces of cos^6 shape."""
    rng = np.random.default_rng(20110101)
    time = np.arange(50) * 1e-6
    rows = []
    for shot, kind, right in ((0, "collision", 0.3), (1, "reference", 0.0)):
        rows.append(
            pd.DataFrame(
                {
                    "source": "simulation",
                    "model": "elastic",
                    "N": 26,
                    "shot": shot,
                    "kind": kind,
                    "amplitude": 0,
                    "v0_left_m_s": 0.3,
                    "v0_right_m_s": right,
                    "t_s": time,
                    sensor_column(10): 200 * np.cos((time - 20e-6) / 15e-6) ** 6,
                    sensor_column(17): rng.normal(0.0, 1.0, time.size),
                }
            )
        )
    return pd.concat(rows, ignore_index=True)


def test_round_trip_keeps_every_value(traces, tmp_path, tol):
    """write_traces then read_traces gives back the table (10 significant digits)."""
    path = tmp_path / "sub" / "traces.csv"
    write_traces(traces, path)
    back = read_traces(path)
    assert list(back.columns) == list(traces.columns)
    pd.testing.assert_frame_equal(
        back, validate_traces(traces), check_exact=False, rtol=tol.csv_round_trip
    )
    # Atomic write: no temporary file is left beside the result.
    assert [p.name for p in path.parent.iterdir()] == ["traces.csv"]


def test_round_trip_is_byte_stable(traces, tmp_path):
    """Writing the same table twice gives the same bytes (reproducible outputs)."""
    write_traces(traces, tmp_path / "a.csv")
    write_traces(read_traces(tmp_path / "a.csv"), tmp_path / "b.csv")
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()


@pytest.mark.parametrize("shots", [(0, 1), (1,)], ids=["both kinds", "reference only"])
def test_unchecked_read_gives_the_checked_table(traces, tmp_path, shots):
    """read_traces(check=False), for files write_traces wrote (a job's inputs), gives the
    table the checked read gives: the same values and dtypes, to the bit. With reference
    shots only, v0_right_m_s is written "0" on every row and must still come back float."""
    path = tmp_path / "traces.csv"
    write_traces(traces[traces["shot"].isin(shots)], path)
    checked, unchecked = read_traces(path), read_traces(path, check=False)
    pd.testing.assert_frame_equal(unchecked, checked, check_exact=True)
    assert unchecked["v0_right_m_s"].dtype == float


def test_simulated_traces_follow_the_format(tmp_path, tol):
    """A simulation's trace table validates, round-trips, and carries the felt force."""
    result = simulate(uniform_chain(26), [0.1, 0.2], [0.1, 0.2], duration=2e-4)
    table = trace_table(result, [10, 17], kind="collision", model_name="elastic")
    assert list(table.columns) == [*META_COLUMNS, "force_bead10_N", "force_bead17_N"]
    write_traces(table, tmp_path / "sim.csv")
    back = read_traces(tmp_path / "sim.csv")
    assert sensor_beads(back) == [10, 17]
    shots = list(iter_shots(back))
    assert [shot for shot, *_ in shots] == [0, 1]
    _, meta, time, forces = shots[1]
    assert meta["kind"] == "collision" and meta["v0_left_m_s"] == 0.2
    np.testing.assert_allclose(time, result.time, rtol=tol.csv_round_trip)
    np.testing.assert_allclose(
        forces[10], result.force_felt(10)[1], rtol=tol.csv_round_trip, atol=1e-300
    )


def test_missing_column_is_named(traces):
    """A table without a required column is rejected and the column is named."""
    with pytest.raises(TraceFormatError, match=r"missing columns .*'t_s'"):
        validate_traces(traces.drop(columns="t_s"))
    with pytest.raises(TraceFormatError, match="no sensor column"):
        validate_traces(traces.drop(columns=[sensor_column(10), sensor_column(17)]))


def test_non_monotonic_time_names_the_shot(traces):
    """Time must increase strictly within a shot; the message names the shot."""
    bad = traces.copy()
    bad.loc[bad.index[60:62], "t_s"] = bad.loc[bad.index[60:62], "t_s"].to_numpy()[::-1]
    with pytest.raises(TraceFormatError, match="shot 1: time is not strictly increasing"):
        validate_traces(bad)


def test_uneven_sampling_names_the_shot(traces):
    """A shot must be evenly sampled; the message names the shot."""
    bad = traces.copy()
    bad.loc[bad.index[10], "t_s"] += 0.3e-6
    with pytest.raises(TraceFormatError, match="shot 0: time is not evenly sampled"):
        validate_traces(bad)


@pytest.mark.parametrize("column", ["t_s", "force_bead17_N"])
@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_non_finite_value_names_the_column(traces, column, value):
    """NaN or infinite times and forces are rejected; the message names the column and row."""
    bad = traces.copy()
    bad.loc[bad.index[7], column] = value
    with pytest.raises(
        TraceFormatError, match=rf"column {column} .* non-finite value at data row 8"
    ):
        validate_traces(bad, where="shots.csv")


@pytest.mark.parametrize(
    ("column", "value", "message"),
    [
        ("kind", "crossing", "kind must be one of"),
        ("source", "lab", "source must be one of"),
        ("shot", 1.5, "column shot must hold integers"),
        ("N", 3, "sensor columns \\(beads \\[10, 17\\]\\): bead 10 is outside the chain 1..3"),
    ],
)
def test_bad_metadata_is_named(traces, column, value, message):
    """Unknown kind or source, non-integer ids and sensors outside the chain are rejected."""
    bad = traces.copy()
    bad[column] = value
    with pytest.raises(TraceFormatError, match=message):
        validate_traces(bad)


def test_sensor_columns_must_put_s1_first(traces):
    """S1 is the first sensor column and the left-launched wave meets it first, so the
    sensor columns run in increasing bead order; the message says so."""
    swapped = traces[[*META_COLUMNS, "force_bead17_N", "force_bead10_N"]]
    with pytest.raises(TraceFormatError, match=r"strictly increasing \(S1 first\), got \[17, 10\]"):
        validate_traces(swapped)


def test_error_messages_say_which_file(traces, tmp_path):
    """read_traces names the file it could not read."""
    with pytest.raises(TraceFormatError, match="no such trace file"):
        read_traces(tmp_path / "absent.csv")
    path = tmp_path / "bad.csv"
    traces.drop(columns="kind").to_csv(path, index=False)
    with pytest.raises(TraceFormatError, match=f"{path.name}: missing columns"):
        read_traces(path)
