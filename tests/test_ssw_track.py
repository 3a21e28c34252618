"""The SSW tracked along simulated chains: is it a solitary wave, and does it obey the
chain's symmetries?

Physics checked: once detached from the crossed pulse, the SSW runs at Eq. 5's speed for
its own amplitude; in the conservative Hertz chain launched by V0 on the end beads the
dynamics is self-similar (F ~ V0^(6/5), t ~ V0^(-1/5)), so the SSW is a fixed fraction
of F_m; and it is larger where the waves cross at a contact (even N) than at a bead.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chain.analysis.ssw_speed import ssw_speed_table
from chain.analysis.ssw_track import ssw_track_table, track_collision
from chain.physics.builders import uniform_chain
from chain.physics.materials import STEEL_100C6
from chain.physics.simulation import simulate
from chain.physics.theory import cos6_pulse, nesterenko_speed_from_force

RADIUS_M = 13e-3
#: Tracked SSW speed against Eq. 5 at its own amplitude (the brief's 5 %). Measured:
#: 1.016 for N = 60, 1.018 for N = 120; Eq. 5 is a long-wavelength approximation that
#: puts the main pulse itself 1.3 % slow.
SPEED_TOLERANCE = 0.05
#: Settled SSW speed / Eq. 5 against the main pulse's own (both 1.013, measured; the
#: recorded times are whole microseconds, ~0.1 % of the 100 us per contact).
SETTLED_SPEED_TOLERANCE = 0.003
#: SSW / F_m at two launch speeds a factor 5 apart (scaling symmetry). With samples at
#: scaled times the only differences are rounding (measured 3e-11).
SCALING_TOLERANCE = 1e-3


def track(n_beads, v0=0.3, record_interval=1e-6, duration=None):
    duration = duration or n_beads * 60e-6 + 1.5e-3
    result = simulate(
        uniform_chain(n_beads),
        v0,
        v0,
        duration=duration,
        record_interval=record_interval,
    )
    return ssw_track_table(result.time, result.contact_force, source="simulation", model="elastic")


def eq5(force):
    return nesterenko_speed_from_force(force, STEEL_100C6, RADIUS_M)


@pytest.fixture(scope="module")
def long_even():
    return track(60)


def test_detached_ssw_runs_at_eq5_speed(long_even):
    speeds = ssw_speed_table(long_even, eq5, 2 * RADIUS_M)
    assert len(speeds) == 2  # LSTW, RSTW
    for row in speeds.itertuples():
        assert row.n_contacts >= 5
        assert row.ratio == pytest.approx(1.0, abs=SPEED_TOLERANCE)
        # The SSW first stands out 4 beads past the collision contact, and detaches later.
        assert row.distance_beads == 4.0
        assert row.first_detached_contact is not None


def test_the_shortest_long_chain_the_schema_allows_is_the_shortest_that_separates_an_ssw():
    """long_chains.N starts at the shortest elastic chain whose SSW separates from the
    main pulses (a run of linked maxima behind them): none at N = 25, at any speed (the
    dynamics is self-similar in V0), one at N = 26 (even chains cross at a contact)."""
    import yaml

    schema_file = Path(__file__).resolve().parents[1] / "workflow/schemas/config.schema.yaml"
    schema = yaml.safe_load(schema_file.read_text())
    shortest = schema["properties"]["long_chains"]["properties"]["N"]["items"]["minimum"]
    assert not track(shortest - 1)["separated"].any()
    assert track(shortest)["separated"].any()


def test_ssw_is_proportional_to_the_incident_amplitude():
    # Samples at times scaled like the dynamics, so both runs see the same points.
    slow, fast = 0.1, 0.5
    scale = (fast / slow) ** (-1.0 / 5.0)
    a = track(26, slow, 1e-6, 3.0e-3)
    b = track(26, fast, 1e-6 * scale, 3.0e-3 * scale)
    assert a["separated"].any()
    assert (a["separated"] == b["separated"]).all()
    separated = a["separated"].to_numpy()
    ratio_a = (a["force_N"] / a["F_m_N"]).to_numpy()[separated]
    ratio_b = (b["force_N"] / b["F_m_N"]).to_numpy()[separated]
    np.testing.assert_allclose(ratio_b, ratio_a, rtol=SCALING_TOLERANCE)
    assert b["F_m_N"].iloc[0] / a["F_m_N"].iloc[0] == pytest.approx(5.0**1.2, rel=1e-3)
    np.testing.assert_allclose(
        b["time_us"].to_numpy()[separated], a["time_us"].to_numpy()[separated] * scale, rtol=1e-6
    )


def test_ssw_larger_when_waves_cross_at_a_contact(long_even):
    # Sec. V: the energy left at the colliding contact (even N) makes a larger SSW.
    odd = track(61)

    def settled(table):
        rows = table[table["detached"] & (table["wave"] == "LSTW")]
        return float((rows["force_N"] / rows["F_m_N"]).median())

    assert settled(long_even) > 2.0 * settled(odd) > 0


def test_paper_chains_even_separates_odd_does_not():
    # In the paper's chains only 12 beads follow the collision: the 26-bead chain's SSW
    # stands out from contact 17 (and its mirror 9) on, the 25-bead chain's nowhere.
    odd, even = track(25), track(26)
    assert not odd["separated"].any()
    lstw = even[even["wave"] == "LSTW"].set_index("contact")
    rstw = even[even["wave"] == "RSTW"].set_index("contact")
    first = lstw.index[lstw["separated"]].min()
    assert first == 17
    # Mirror symmetry: RSTW at contact N - k is LSTW at k.
    np.testing.assert_allclose(
        rstw.loc[26 - lstw.index, "force_N"].to_numpy(), lstw["force_N"].to_numpy(), rtol=1e-9
    )


def scipy_first_bump(signal, main_index, window_s, floor_N, time):
    """The scipy.signal.find_peaks formulation _first_bump replaces."""
    from scipy.signal import find_peaks

    peaks, _ = find_peaks(signal[main_index:], height=floor_N, prominence=floor_N)
    peaks = peaks[time[main_index + peaks] - time[main_index] <= window_s]
    return int(main_index + peaks[0]) if peaks.size else -1


@settings(max_examples=300, deadline=None)
@given(
    st.lists(st.integers(0, 6), min_size=1, max_size=60),
    st.integers(0, 59),
    st.floats(0.0, 70.0),
    st.floats(0.0, 4.0),
)
def test_first_bump_is_the_first_peak_find_peaks_gives(levels, main, window, floor):
    # Small integer levels: plateaus, equal neighbours and ties of every kind.
    from chain.analysis.ssw_track import _first_bump

    signal = np.asarray(levels, dtype=float) * 0.5
    time = np.arange(signal.size) * 1.0
    main = min(main, signal.size - 1)
    expected = scipy_first_bump(signal, main, window, floor, time)
    assert _first_bump(signal, main, window, floor, time) == expected


def test_first_bump_on_contact_forces_agrees_with_find_peaks():
    from chain.analysis.ssw_track import _first_bump

    model = uniform_chain(26, STEEL_100C6, 4.76e-3, 0.0)
    result = simulate(model, [0.3], [0.3], duration=1.5e-3, record_interval=1e-6)
    force, time = result.contact_force[0], result.time
    rng = np.random.default_rng(3)
    for k in range(force.shape[1]):
        noisy = force[:, k] + rng.normal(0, 1e-3 * force.max(), force.shape[0])
        for signal in (force[:, k], noisy):
            main = int(np.argmax(signal))
            for floor in (1e-4, 1e-3, 1e-2, 0.05):
                args = (signal, main, 4e-4, floor * signal.max(), time)
                assert _first_bump(*args) == scipy_first_bump(*args)


# ---- one definition of "separated", on synthetic fields ---------------------------
#: Synthetic chain: N beads, a pulse of width TAU_S crossing one contact per STEP_S.
SYN_N, STEP_S, TAU_S, SYN_F = 41, 50e-6, 40e-6, 100.0
SYN_TIME = np.arange(0.0, 4.5e-3, 1e-6)


def synthetic_field(small=0.0, tail=0.0):
    """Contact forces (samples, N-1) of two equal pulses launched from the ends, meeting
    at the middle contact at t_c: each a cos^6 pulse moving one contact per STEP_S;
    ``small`` adds, behind each crossed pulse, a solitary wave of that fraction of F
    born at the collision point and moving at Eq. 5's speed for its size (F^(1/6):
    STEP_S small^(-1/6) per contact, width TAU_S small^(-1/6)); ``tail`` adds a
    Kuwabara-Kono-like tail behind every pulse, ``tail`` F decaying over 10 STEP_S,
    monotonic (the larger of pulse and tail)."""
    contacts = np.arange(1, SYN_N)
    centre = SYN_N / 2.0  # contact SYN_N / 2 sits at the collision point
    t_c = 1.5e-3
    field = np.zeros((SYN_TIME.size, contacts.size))
    for direction in (1, -1):
        distance = direction * (contacts - centre)  # downstream > 0
        for k, d in enumerate(distance):
            arrival = t_c + d * STEP_S
            pulse = cos6_pulse(SYN_TIME, SYN_F, arrival, TAU_S)
            behind = SYN_TIME - arrival
            decay = tail * SYN_F * np.exp(-np.where(behind > 0, behind, np.inf) / (10 * STEP_S))
            field[:, k] += np.maximum(pulse, decay)
            if small and d > 0:
                width = TAU_S * small ** (-1.0 / 6.0)
                late = t_c + d * STEP_S * small ** (-1.0 / 6.0)
                field[:, k] += cos6_pulse(SYN_TIME, small * SYN_F, late, width)
    return field


def test_synthetic_pair_small_wave_is_separated_and_plain_pulse_is_not():
    plain = track_collision(SYN_TIME, synthetic_field())
    assert not any(found["separated"].any() for found in plain.values())
    pair = track_collision(SYN_TIME, synthetic_field(small=0.02))
    for found in pair.values():
        separated = found["separated"]
        # Separated from where it trails the main pulse by more than both widths, on.
        assert separated[-8:].all()
        rows = np.flatnonzero(separated)
        np.testing.assert_allclose(found["force_N"][rows], 0.02 * SYN_F, rtol=0.02)


def test_kuwabara_kono_tail_alone_is_not_an_ssw():
    """A monotonic tail behind every pulse has no maximum to track."""
    for level in (0.01, 0.05):
        found = track_collision(SYN_TIME, synthetic_field(tail=level))
        assert not any(f["separated"].any() for f in found.values())
    # The tail does not hide a real SSW either.
    found = track_collision(SYN_TIME, synthetic_field(small=0.02, tail=0.01))
    assert all(f["separated"][-8:].all() for f in found.values())


def test_viscoelastic_paper_chain_has_no_ssw():
    """The paper's odd chain with Kuwabara-Kono dissipation at its strongest launch: the
    contact that opens and closes 1.5-2.5 beads behind the crossed pulse (two contacts,
    moving at half the speed of a wave its size) is not a separated SSW."""
    model = uniform_chain(25, STEEL_100C6, RADIUS_M, 0.58e-6)
    result = simulate(model, 1.0, 1.0, duration=2.6e-3, record_interval=1e-6)
    table = ssw_track_table(result.time, result.contact_force, source="s", model="visco")
    assert not table["separated"].any()


def test_settled_ssw_runs_at_the_main_pulses_own_eq5_ratio():
    """Far from the collision point the SSW is a solitary wave: fitted where it has
    settled (20 beads on, before the main pulse reaches the end), its speed over Eq. 5
    for its own amplitude is that of the main pulse (Eq. 5 is a long-wavelength
    approximation; measured 1.013 both). Fitted from where it detaches the ratio is
    larger (1.02 even, 1.03 odd: it is still growing there)."""
    rows = track(120, 0.3, duration=9e-3)
    rows = rows[(rows["wave"] == "LSTW")].sort_values("distance_beads")
    end = rows["main_time_us"].iloc[-2]
    settled = rows[rows["detached"] & (rows["distance_beads"] >= 20) & (rows["time_us"] < end)]
    assert len(settled) >= 10

    def ratio(distance, time_us, force):
        speed = 2 * RADIUS_M / np.polyfit(distance, time_us * 1e-6, 1)[0]
        return speed / eq5(float(np.mean(force)))

    ssw = ratio(settled["distance_beads"], settled["time_us"], settled["force_N"])
    main = rows[(rows["distance_beads"] >= 5) & (rows["distance_beads"] <= 40)]
    pulse = ratio(main["distance_beads"], main["main_time_us"], main["main_force_N"])
    assert ssw == pytest.approx(pulse, abs=SETTLED_SPEED_TOLERANCE)
