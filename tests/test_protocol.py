"""The paper's 5 % acceptance protocol on hand-made pulse tables."""

import math

import numpy as np
import pandas as pd
import pytest

from chain.analysis.selection import SELECTION_COLUMNS, amplitude_mismatch, select_shots
from chain.errors import ParameterError


def _pulse(shot, kind, sensor, role, force, ok=True, reason="", estimator="fit_full"):
    wave = "LSTW" if (sensor == "S1") == (role == "incident") or role == "reference" else "RSTW"
    return {
        "source": "experiment",
        "model": "lab",
        "N": 25,
        "shot": shot,
        "kind": kind,
        "amplitude": 0,
        "sensor": sensor,
        "bead": 9 if sensor == "S1" else 17,
        "role": role,
        "wave": wave,
        "estimator": estimator,
        "F_m_N": force if ok else math.nan,
        "T_s": 1e-3,
        "tau_s": 1e-4,
        "ok": ok,
        "reason": reason,
    }


def _collision(shot, left, right, **kwargs):
    return [
        _pulse(shot, "collision", "S1", "incident", left, **kwargs),
        _pulse(shot, "collision", "S1", "crossed", 0.95 * right, **kwargs),
        _pulse(shot, "collision", "S2", "incident", right, **kwargs),
        _pulse(shot, "collision", "S2", "crossed", 0.95 * left, **kwargs),
    ]


def _reference(shot, force, ok=True, reason=""):
    return [
        _pulse(shot, "reference", "S1", "reference", force, ok, reason),
        _pulse(shot, "reference", "S2", "reference", 0.97 * force),
    ]


@pytest.fixture
def pulses():
    rows = (
        _collision(0, 30.0, 30.6)  # 2.0 % kept
        + _collision(1, 30.0, 32.2305)  # 7.2 % rejected
        + _collision(2, 30.0, 30.0)
        + _reference(3, 30.5)
        + _reference(4, 30.5, ok=False, reason="fit did not converge")
    )
    # shot 2: no incident pulse found at S2
    rows[2 * 4 + 2].update(ok=False, F_m_N=math.nan, reason="no pulse detected")
    return pd.DataFrame(rows)


def test_ok_flag_read_as_text_gives_the_same_selection(pulses):
    """``ok`` as text ("True"/"False") is read like the booleans: "False" rejects."""
    as_text = pulses.assign(ok=pulses["ok"].map({True: "True", False: "False"}))
    pd.testing.assert_frame_equal(select_shots(as_text), select_shots(pulses))


def test_mismatch_definition():
    assert amplitude_mismatch(30.0, 30.6) == pytest.approx(0.6 / 30.3)
    assert amplitude_mismatch(10.0, 10.0) == 0.0


def test_selection_keeps_matched_and_rejects_mismatched(pulses):
    selection = select_shots(pulses)
    assert list(selection.columns) == list(SELECTION_COLUMNS)
    assert list(selection["shot"]) == [0, 1, 2, 3, 4]
    row = selection.set_index("shot")
    assert row.loc[0, "kept"]
    assert row.loc[0, "mismatch"] == pytest.approx(0.6 / 30.3)
    assert row.loc[0, "F_left_N"] == 30.0 and row.loc[0, "F_right_N"] == 30.6
    assert not row.loc[1, "kept"]
    assert row.loc[1, "reason"] == "amplitude mismatch 7.2% > 5%"
    assert not row.loc[2, "kept"]
    assert "no pulse detected" in row.loc[2, "reason"] and "S2" in row.loc[2, "reason"]
    assert row.loc[3, "kept"] and np.isnan(row.loc[3, "mismatch"])
    assert row.loc[3, "F_left_N"] == 30.5
    assert not row.loc[4, "kept"] and "fit did not converge" in row.loc[4, "reason"]
    assert selection["kept"].dtype == bool


def test_tolerance_is_configurable(pulses):
    selection = select_shots(pulses, tolerance=0.10).set_index("shot")
    assert selection.loc[1, "kept"]
    assert selection.loc[1, "reason"] == "kept: amplitude mismatch 7.2% <= 10%"
    strict = select_shots(pulses, tolerance=0.01).set_index("shot")
    assert not strict.loc[0, "kept"]


def test_mismatch_equal_to_tolerance_is_kept():
    left = 30.0
    right = left * (1 + 0.05 / 2) / (1 - 0.05 / 2)  # |L - R| / mean = 5 % exactly
    selection = select_shots(pd.DataFrame(_collision(0, left, right)))
    assert selection.loc[0, "mismatch"] == pytest.approx(0.05)
    assert selection.loc[0, "kept"]


def test_other_estimator_is_selectable(pulses):
    other = pd.DataFrame(_collision(0, 30.0, 40.0, estimator="peak"))
    both = pd.concat([pulses, other], ignore_index=True)
    assert select_shots(both).set_index("shot").loc[0, "kept"]
    peak = select_shots(both, estimator="peak")
    assert len(peak) == 1 and not peak.loc[0, "kept"]
    with pytest.raises(ParameterError, match="no rows for estimator 'fit_rise'"):
        select_shots(both, estimator="fit_rise")


def test_shots_without_pulse_rows_are_rejected_rows(pulses):
    shots = pd.DataFrame(
        {
            "source": "experiment",
            "model": "lab",
            "N": 25,
            "shot": [0, 5, 5],
            "kind": "collision",
            "amplitude": 0,
        }
    )
    selection = select_shots(pulses, shots=shots).set_index("shot")
    assert not selection.loc[5, "kept"]
    assert selection.loc[5, "reason"].startswith("no pulse detected")


@pytest.mark.parametrize("tolerance", [-0.01, math.nan, "5%", True])
def test_bad_tolerance(pulses, tolerance):
    with pytest.raises(ParameterError, match="tolerance"):
        select_shots(pulses, tolerance=tolerance)


def test_missing_pulse_columns():
    with pytest.raises(ParameterError, match=r"missing columns \['F_m_N'\]"):
        select_shots(pd.DataFrame(_collision(0, 1.0, 1.0)).drop(columns="F_m_N"))
