"""Delta per shot from synthetic traces with known times of flight, and its fits."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from chain.analysis.delays import DELAY_COLUMNS, DELAY_FIT_COLUMNS, delay_fit_table, delay_table
from chain.analysis.pulse_rows import pulse_table
from chain.analysis.recipe import fit_delays, fit_pulses
from chain.errors import ParameterError
from chain.physics.theory import cos6_pulse
from chain.traces import META_COLUMNS, sensor_column, validate_traces

TIME_S = np.arange(0.0, 1200e-6, 1e-6)
TAU_S = 80e-6
TOF_REFERENCE_S = 400e-6  # S1 -> S2 of the single wave
FIRST_ARRIVAL_S = 250e-6  # incident waves at the first sensor they meet
F_LEFT_N, F_RIGHT_N = 500.0, 450.0  # incident LSTW at S1, RSTW at S2

#: Noise-free synthetic pulses are exact cos^6: delays recovered to round-off.
EXACT_US = 1e-6
#: Largest standard error of a delay at SNR 100: it combines four arrival times, each
#: ~0.06 us (fit_full), 0.16 us (peak), 0.40 us (fit_rise) (tests/test_pulses.py).
NOISY_STDERR_US = {"fit_full": 0.3, "peak": 0.6, "fit_rise": 1.5}
#: A recovered shift lies within this many of its standard errors.
N_STDERR = 4.0


def shot(shot_id, kind, amplitude, s1, s2, n_beads=25):
    return pd.DataFrame(
        {
            "source": "simulation",
            "model": "synthetic",
            "N": n_beads,
            "shot": shot_id,
            "kind": kind,
            "amplitude": amplitude,
            "v0_left_m_s": 1.0,
            "v0_right_m_s": 1.0 if kind == "collision" else 0.0,
            "t_s": TIME_S,
            sensor_column(9): s1,
            sensor_column(17): s2,
        }
    )[[*META_COLUMNS, sensor_column(9), sensor_column(17)]]


def pulse(force, arrival):
    return cos6_pulse(TIME_S, force, arrival, TAU_S)


def synthetic_traces(shift_left_s, shift_right_s, *, noise=0.0, seed=0, n_references=1):
    """A collision shot whose crossed LSTW (RSTW) arrives ``shift`` after the reference
    time of flight, and reference shots of the same amplitude."""
    rng = np.random.default_rng(seed)
    crossed_at = FIRST_ARRIVAL_S + TOF_REFERENCE_S
    s1 = pulse(F_LEFT_N, FIRST_ARRIVAL_S) + pulse(0.98 * F_RIGHT_N, crossed_at + shift_right_s)
    s2 = pulse(F_RIGHT_N, FIRST_ARRIVAL_S) + pulse(0.98 * F_LEFT_N, crossed_at + shift_left_s)
    shots = [shot(0, "collision", 0, s1, s2)]
    for k in range(n_references):
        # Reference shots start at another time origin: only times of flight matter.
        start = FIRST_ARRIVAL_S - 20e-6 * k
        shots.append(
            shot(
                1 + k,
                "reference",
                0,
                pulse(F_LEFT_N, start),
                pulse(F_LEFT_N, start + TOF_REFERENCE_S),
            )
        )
    table = pd.concat(shots, ignore_index=True)
    for column in (sensor_column(9), sensor_column(17)):
        table[column] += 1.5 + rng.normal(0.0, noise, len(table))
    return validate_traces(table)


def delays_of(traces, estimators=("fit_full",), selection=None):
    return delay_table(pulse_table(traces, estimators=estimators), selection=selection)


def test_identical_crossed_and_reference_give_zero_delay():
    delays = delays_of(synthetic_traces(0.0, 0.0, n_references=2))
    assert tuple(delays.columns) == DELAY_COLUMNS
    assert delays["ok"].all()
    assert len(delays) == 2  # LSTW and RSTW
    assert np.allclose(delays["delay_us"], 0.0, atol=EXACT_US)
    assert (delays["n_reference"] == 2).all()


def test_known_shifts_recovered_with_sign_and_first_sensor_amplitude():
    delays = delays_of(synthetic_traces(-12e-6, -7e-6)).set_index("wave")
    assert delays.loc["LSTW", "delay_us"] == pytest.approx(-12.0, abs=EXACT_US)
    assert delays.loc["RSTW", "delay_us"] == pytest.approx(-7.0, abs=EXACT_US)
    assert delays.loc["LSTW", "F_m_N"] == pytest.approx(F_LEFT_N, rel=1e-9)
    assert delays.loc["RSTW", "F_m_N"] == pytest.approx(F_RIGHT_N, rel=1e-9)
    assert delays.loc["LSTW", "tof_reference_us"] == pytest.approx(400.0, abs=EXACT_US)


@pytest.mark.parametrize("estimator", ["fit_full", "peak", "fit_rise"])
def test_known_shift_recovered_from_noisy_traces(estimator):
    traces = synthetic_traces(-10e-6, -10e-6, noise=5.0, seed=4)
    delays = delays_of(traces, estimators=(estimator,))
    assert delays["ok"].all()
    error = (delays["delay_us"] + 10.0).abs()
    assert (error < N_STDERR * delays["delay_stderr_us"]).all()
    assert (delays["delay_stderr_us"] < NOISY_STDERR_US[estimator]).all()


def test_selection_drops_rejected_collision_shots():
    traces = synthetic_traces(-5e-6, -5e-6)
    selection = pd.DataFrame({"shot": [0, 1], "kept": [False, True]})
    assert delays_of(traces, selection=selection).empty
    kept = pd.DataFrame({"shot": [0], "kept": [True]})
    assert len(delays_of(traces, selection=kept)) == 2


def test_missing_reference_or_pulse_gives_flagged_rows():
    traces = synthetic_traces(-5e-6, -5e-6)
    collision_only = validate_traces(traces[traces["kind"] == "collision"])
    delays = delays_of(collision_only)
    assert not delays["ok"].any()
    assert delays["reason"].str.contains("reference").all()
    assert delays["delay_us"].isna().all()
    silent = traces.copy()
    silent.loc[silent["shot"] == 0, sensor_column(17)] = 1.5  # S2 sees nothing
    flagged = delays_of(validate_traces(silent))
    assert not flagged["ok"].any()
    assert flagged["reason"].str.contains("no pulse detected").all()


def test_ok_flag_read_as_text_gives_the_same_delays():
    """A pulses table whose ``ok`` column holds text ("True"/"False", as a hand-edited
    or re-typed CSV may) gives the same delays: the text "False" flags the pulse."""
    pulses = pulse_table(synthetic_traces(-5e-6, -5e-6, n_references=2))
    # Flag the incident LSTW pulse at S1 of the collision shot.
    flagged = (pulses["shot"] == 0) & (pulses["sensor"] == "S1") & (pulses["role"] == "incident")
    pulses.loc[flagged, ["ok", "reason"]] = [False, "flagged by hand"]
    as_text = pulses.assign(ok=pulses["ok"].map({True: "True", False: "False"}))
    expected = delay_table(pulses)
    pd.testing.assert_frame_equal(delay_table(as_text), expected)
    assert list(expected.set_index("wave")["ok"]) == [False, True]


def synthetic_delay_rows(constant_us, forces, n_beads, exponent=-1.0 / 6.0):
    rows = []
    for i, force in enumerate(forces):
        for wave in ("LSTW", "RSTW"):
            rows.append(
                {
                    "source": "simulation",
                    "model": "synthetic",
                    "N": n_beads,
                    "shot": i,
                    "amplitude": i,
                    "wave": wave,
                    "estimator": "fit_full",
                    "F_m_N": force,
                    "delay_us": -constant_us * force**exponent,
                    "ok": True,
                }
            )
    return pd.DataFrame(rows)


def test_delay_fit_table_recovers_c_and_exponent_per_n_and_pooled():
    forces = np.geomspace(10.0, 1000.0, 7)
    delays = pd.concat(
        [synthetic_delay_rows(40.0, forces, 25), synthetic_delay_rows(38.0, forces, 26)],
        ignore_index=True,
    )
    delays.loc[delays.index[:1], "ok"] = False  # a flagged row is left out
    fits = delay_fit_table(delays)
    assert tuple(fits.columns) == DELAY_FIT_COLUMNS
    by_n = fits.set_index("N")
    assert by_n.loc[25, "C_us_N16"] == pytest.approx(40.0, rel=1e-12)
    assert by_n.loc[26, "C_us_N16"] == pytest.approx(38.0, rel=1e-12)
    assert by_n.loc[25, "exponent"] == pytest.approx(-1.0 / 6.0, abs=1e-12)
    assert by_n.loc[25, "n_points"] == 13
    assert by_n.loc[26, "n_points"] == 14
    assert by_n.loc["pooled", "n_points"] == 27
    assert 38.0 < by_n.loc["pooled", "C_us_N16"] < 40.0


def test_delay_fit_table_small_groups_give_nan():
    delays = synthetic_delay_rows(40.0, [100.0], 25)  # 2 points (LSTW, RSTW), one force
    fits = delay_fit_table(delays).set_index("N")
    assert fits.loc[25, "n_points"] == 2
    assert math.isfinite(fits.loc[25, "C_us_N16"])
    assert math.isnan(fits.loc[25, "exponent"])


def test_recipe_leaves_unusable_rows_out_where_the_fit_would_refuse_them():
    """The recipe's row policy (chain.analysis.recipe.fit_delays): an ``ok`` row with a
    NaN delay or force is left out of the fits, which alone refuse it."""
    forces = np.geomspace(10.0, 1000.0, 5)
    clean = synthetic_delay_rows(40.0, forces, 25)
    broken = clean.iloc[:2].assign(delay_us=[np.nan, -30.0], F_m_N=[100.0, np.inf])
    delays = pd.concat([clean, broken], ignore_index=True)
    with pytest.raises(ParameterError, match="finite"):
        delay_fit_table(delays)
    fits = fit_delays(delays)
    pd.testing.assert_frame_equal(fits, delay_fit_table(clean), check_exact=True)
    assert fits.set_index("N").loc[25, "n_points"] == 10
    assert delays["ok"].all()  # the caller's table is left as it was


def test_recipe_from_pulses_is_the_delay_table_and_its_fits_bit_for_bit():
    """pulses -> delays -> fits (fit_pulses) gives what the steps one by one give, with
    and without a shot selection."""
    traces = synthetic_traces(-6e-6, -4e-6, noise=3.0, seed=2, n_references=2)
    pulses = pulse_table(traces, estimators=("fit_full", "peak"))
    for selection in (None, pd.DataFrame({"shot": [0], "kept": [True]})):
        expected = delay_fit_table(delay_table(pulses, selection=selection))
        pd.testing.assert_frame_equal(fit_pulses(pulses, selection), expected, check_exact=True)
