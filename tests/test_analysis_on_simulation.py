"""The analysis chain on real simulator output: conservative chains of 25 and 26 beads.

With V0 on the end beads, free ends and no dissipation the Hertz chain is exactly
self-similar (F ~ V0^(6/5), t ~ V0^(-1/5)), so every delay must scale as F_m^(-1/6)
and every SSW as F_m: the fitted exponent tests the estimators' scale covariance on
sampled data (1 us sampling, tau from ~70 to ~180 us), not the physics.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import chain
from chain.analysis.delays import delay_fit_table, delay_table
from chain.analysis.pulse_rows import pulse_table
from chain.analysis.ssw import ssw_fit_table, ssw_table
from chain.physics.theory import ballistic_delay_constant_exact

#: Launch speeds: F_m from ~9 N to ~1 kN at the first sensor.
SPEEDS_M_S = np.geomspace(0.02, 1.0, 7)
#: Long enough for the weakest crossed wave (~300 m/s) to pass S2.
DURATION_S = 2.6e-3
SENSORS = {25: (9, 17), 26: (10, 17)}

#: |p + 1/6| of the free power law (fit_full): the brief asks three decimals; the
#: self-similarity makes it exact up to sampling (measured ~5e-6).
EXPONENT_TOLERANCE = 5e-4
#: C against the ballistic estimate with the exact Hertz contact time (37.7 us N^(1/6)):
#: the ballistic picture is an approximation (measured C / C_bal_exact = 1.10 for
#: N = 25 and 1.02 for N = 26).
C_RATIO_RANGE = (0.9, 1.2)
#: Largest relative spread of SSW / F_m over the amplitudes of a self-similar chain.
SELF_SIMILAR_SPREAD = 0.02


@pytest.fixture(scope="module")
def analysed():
    pulses, delays, ssw = [], [], []
    for n_beads, sensors in SENSORS.items():
        traces, _ = chain.simulate_shots(
            chain.uniform_chain(n_beads),
            SPEEDS_M_S,
            sensors,
            model_name="elastic",
            duration=DURATION_S,
        )
        table = pulse_table(traces, estimators=("fit_full", "peak", "fit_rise"))
        pulses.append(table)
        delays.append(delay_table(table))
        ssw.append(ssw_table(traces, table))
    return (
        pd.concat(pulses, ignore_index=True),
        pd.concat(delays, ignore_index=True),
        pd.concat(ssw, ignore_index=True),
    )


def test_every_pulse_and_delay_is_measured(analysed):
    pulses, delays, _ = analysed
    assert pulses["ok"].all(), pulses.loc[~pulses["ok"], "reason"].unique()
    assert delays["ok"].all()
    # Crossed waves arrive early at every amplitude, with every estimator.
    assert (delays["delay_us"] < 0).all()
    incident = delays[delays["estimator"] == "fit_full"]["F_m_N"]
    assert incident.min() < 12.0 and incident.max() > 900.0


@pytest.mark.parametrize("n_beads", sorted(SENSORS))
def test_delay_exponent_is_minus_one_sixth(analysed, n_beads):
    fits = delay_fit_table(analysed[1])
    row = fits[(fits["N"] == n_beads) & (fits["estimator"] == "fit_full")].iloc[0]
    assert abs(row["exponent"] + 1.0 / 6.0) < EXPONENT_TOLERANCE, row["exponent"]
    ratio = row["C_us_N16"] / (ballistic_delay_constant_exact(chain.STEEL_100C6, 13e-3) * 1e6)
    assert C_RATIO_RANGE[0] < ratio < C_RATIO_RANGE[1], row["C_us_N16"]


def test_ssw_measured_not_resolved_and_self_similar(analysed):
    # Four beads from the collision point the SSW is still a shoulder on the crossed
    # pulse: it separates from contact 17 of the 26-bead chain on and nowhere in the
    # 25-bead one (tests/test_ssw_track.py). So it is measured (with its error) at every
    # amplitude, resolved at none; the elastic chain is self-similar, so SSW / F_m is the
    # same at every amplitude up to the sampling (measured spread 0.8 % and 0.5 % of
    # the mean for N = 25 and 26), and the even chain's is the larger.
    ssw = analysed[2]
    residual = ssw[ssw["method"] == "residual"]
    assert residual["ok"].all() and not ssw["resolved"].any()
    ratio = residual["ssw_N"] / residual["F_m_N"]
    spread = ratio.groupby(residual["N"]).agg(lambda r: r.std() / r.mean())
    assert (spread < SELF_SIMILAR_SPREAD).all(), spread
    fits = ssw_fit_table(ssw).set_index("N")
    assert (fits["n_points"] == 2 * len(SPEEDS_M_S)).all()
    assert fits.loc[26, "slope"] > fits.loc[25, "slope"]
