"""Physics of simulated chains: conservation laws, exact two-body results, Nesterenko's
solitary wave (Eq. 4-5), the Hertz scaling symmetry, Kuwabara-Kono, sensor beads."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chain import (
    ParameterError,
    default_time_step,
    simulate,
    uniform_chain,
)
from chain.physics.theory import (
    hertz_contact_time,
    hertz_peak_force,
    nesterenko_speed_from_force,
    solitary_wave_length,
)

#: Launch speeds of the conservation tests, m/s (the paper's range goes up to ~1 m/s).
LAUNCH_SPEEDS = (0.01, 0.1, 0.3, 1.0)

#: The paper's run length, s.
PAPER_DURATION = 2.6e-3


# --------------------------------------------------------------------------- conservation


@pytest.fixture(scope="module", params=LAUNCH_SPEEDS, ids=lambda v: f"V0={v}")
def paper_runs(request):
    """N = 26, eta = 0, default step, 2.6 ms: a collision (+V0, -V0) and a reference
    (+V0 alone) in one batch."""
    speed = request.param
    return simulate(uniform_chain(26), [speed, speed], [speed, 0.0], duration=PAPER_DURATION)


def test_conservative_energy_drift_default_step(paper_runs, tol):
    """Eq. 1 conserves E_kin + E_pot: relative drift <= 1e-9 with the default step."""
    assert paper_runs.dt > 0
    assert np.all(paper_runs.dissipated_energy == 0.0)
    assert np.all(paper_runs.energy_drift <= tol.energy_drift), paper_runs.energy_drift


def test_free_chain_conserves_momentum(paper_runs, bead_mass, tol):
    """Free ends, internal forces: total momentum is 0 for a collision and m V0 for a
    reference launch, to round-off, at every recorded instant."""
    speed = paper_runs.v_left[0]
    scale = bead_mass * speed
    collision, reference = paper_runs.momentum
    assert np.max(np.abs(collision)) <= tol.momentum * scale
    assert np.max(np.abs(reference - scale)) <= tol.momentum * scale


def test_collision_is_mirror_symmetric(paper_runs, tol):
    """Equal and opposite launches on a uniform chain: F_k(t) = F_{N-k}(t) and
    v_n(t) = -v_{N+1-n}(t) (parity of Eq. 1), to round-off."""
    force = paper_runs.contact_force[0]
    velocity = paper_runs.bead_velocity[0]
    np.testing.assert_allclose(force, force[:, ::-1], rtol=0, atol=tol.roundoff * force.max())
    np.testing.assert_allclose(
        velocity, -velocity[:, ::-1], rtol=0, atol=tol.roundoff * paper_runs.v_left[0]
    )
    # The waves did cross: the middle contact (13) carried the largest force of the run.
    assert np.argmax(force.max(axis=0)) + 1 == 13


@pytest.mark.parametrize("speed", [0.1, 1.0])
def test_dissipative_energy_balance(speed, eta, bead_mass, tol):
    """Kuwabara-Kono (eta = 0.58 us): E_kin + E_pot + E_diss is conserved to 1e-9 with the
    default step, E_diss > 0 never decreases, and momentum is still conserved."""
    result = simulate(uniform_chain(26, eta=eta), speed, speed, duration=PAPER_DURATION)
    assert result.energy_drift[0] <= tol.energy_drift
    dissipated = result.dissipated_energy[0]
    assert dissipated[0] == 0.0 and dissipated[-1] > 0.0
    assert np.all(np.diff(dissipated) >= 0.0)
    # A sizeable part of the launch energy (27 % at 0.1 m/s, 38 % at 1 m/s) is lost
    # by the end of the paper's run; more at higher speed (1 - e ~ V^(1/5)).
    assert 0.1 < dissipated[-1] / result.total_energy[0, 0] < 0.5
    assert np.max(np.abs(result.momentum[0])) <= tol.momentum * bead_mass * speed


def test_default_time_step_follows_the_hertz_time():
    """The default step is a fixed fraction of the shortest Hertz contact time, which
    scales as V^(-1/5); a stiff sensor spring can only make it shorter."""
    model = uniform_chain(26)
    ratio = default_time_step(model, 1 / 32) / default_time_step(model, 1.0)
    assert ratio == pytest.approx(32.0**0.2, rel=1e-12)
    sensor = uniform_chain(26, sensor_beads=[10])
    assert default_time_step(sensor, 0.01) <= default_time_step(model, 0.01)


# --------------------------------------------------------------------------- two spheres


@pytest.mark.parametrize("speed", [0.01, 0.1, 1.0])
def test_two_sphere_collision_matches_hertz(speed, bead_mass, kappa, tol, peak_of, release_time):
    """Two equal spheres, one at rest: contact time 2.9432 (5 mu / 4 kappa)^(2/5) v^(-1/5)
    and peak force kappa delta_max^(3/2) (exact Hertz closed forms), peak at t_c / 2."""
    contact_time = hertz_contact_time(bead_mass, bead_mass, kappa, speed)
    dt = contact_time / 2000
    result = simulate(
        uniform_chain(2), speed, 0.0, duration=1.1 * contact_time, dt=dt, record_interval=dt
    )
    force = result.contact(1)[0]
    assert release_time(result.time, force) == pytest.approx(contact_time, rel=tol.hertz_collision)
    peak_time, peak_force = peak_of(result.time, force)
    expected = hertz_peak_force(bead_mass, bead_mass, kappa, speed)
    assert peak_force == pytest.approx(expected, rel=tol.hertz_collision)
    assert peak_time == pytest.approx(contact_time / 2, rel=tol.hertz_collision)


@pytest.mark.parametrize("speed", [0.01, 1.0])
def test_two_equal_spheres_exchange_velocities(speed, bead_mass, kappa, tol):
    """Equal masses, elastic contact: after the collision the striker stops and the target
    leaves with the impact speed."""
    contact_time = hertz_contact_time(bead_mass, bead_mass, kappa, speed)
    result = simulate(uniform_chain(2), speed, 0.0, duration=1.5 * contact_time)
    left, right = result.bead_velocity[0, -1]
    assert abs(left) <= tol.velocity_exchange * speed
    assert right == pytest.approx(speed, rel=tol.velocity_exchange)
    assert result.contact(1)[0, -1] == 0.0


def test_kuwabara_kono_restitution(eta, bead_mass, kappa, tol):
    """Kuwabara-Kono: the restitution coefficient e = separation / approach speed is below
    1 and decreases with impact speed, with 1 - e ~ V^(1/5) (leading order in eta)."""
    speeds = np.array([0.01, 0.1, 1.0])
    restitution = []
    for speed in speeds:
        contact_time = hertz_contact_time(bead_mass, bead_mass, kappa, speed)
        result = simulate(
            uniform_chain(2, eta=eta),
            speed,
            0.0,
            duration=2 * contact_time,
            dt=contact_time / 2000,
            record_interval=contact_time / 20,
        )
        assert result.contact(1)[0, -1] == 0.0  # the beads have separated
        left, right = result.bead_velocity[0, -1]
        restitution.append((right - left) / speed)
    restitution = np.array(restitution)
    assert np.all(restitution < 1.0) and np.all(restitution > 0.9)
    assert np.all(np.diff(restitution) < 0)
    exponent = np.polyfit(np.log(speeds), np.log(1.0 - restitution), 1)[0]
    assert exponent == pytest.approx(0.2, abs=tol.kk_exponent_abs)


# --------------------------------------------------------------------------- solitary wave


@pytest.fixture(scope="module")
def solitary_wave():
    """A single wave (V0 = 0.2 m/s on bead 1) in a conservative chain of N = 60 beads,
    recorded every 0.1 us until it has passed contact 42."""
    return simulate(uniform_chain(60), 0.2, 0.0, duration=2.3e-3, record_interval=1e-7)


#: Contacts used for the speed: far from bead 1 (formation) and from bead 60.
WAVE_CONTACTS = np.arange(16, 42)


def test_solitary_wave_speed_eq5(solitary_wave, steel, radius, tol, peak_of):
    """Eq. 5: the wave runs at (6 / (5 pi rho))^(1/2) (F_m / (theta^2 R^2))^(1/6), speed
    measured from the peak times of contacts 16..41 (spacing 2R), F_m measured too."""
    peaks = np.array(
        [peak_of(solitary_wave.time, solitary_wave.contact(int(k))[0]) for k in WAVE_CONTACTS]
    )
    times, forces = peaks[:, 0], peaks[:, 1]
    # A stationary wave: constant amplitude over the measured stretch.
    assert np.ptp(forces) <= 1e-3 * forces.mean()
    speed = np.polyfit(times, 2.0 * radius * WAVE_CONTACTS, 1)[0]
    expected = nesterenko_speed_from_force(forces.mean(), steel, radius)
    assert speed == pytest.approx(expected, rel=tol.solitary_speed)


def test_solitary_wave_width_is_five_beads(solitary_wave, radius, tol):
    """Eq. 4: the wave is one cos^6 hump of length pi sqrt(10) R ~ 4.97 beads. For that
    profile, sum_k F_k / F_m = (5 pi / 16) (sqrt(10) / 2), so the integral width
    (16 / 5) sum_k F_k / F_m must equal the hump length in beads."""
    force = solitary_wave.contact_force[0]
    expected = solitary_wave_length(radius) / (2.0 * radius)
    for contact in (20, 30, 40):
        instant = int(np.argmax(force[:, contact - 1]))
        profile = force[instant]
        width = 3.2 * profile.sum() / profile.max()
        assert width == pytest.approx(expected, rel=tol.solitary_width)
        # About five contacts carry the wave (force above 1e-3 of its peak).
        assert 4 <= np.count_nonzero(profile > 1e-3 * profile.max()) <= 6


# --------------------------------------------------------------------------- scaling


def test_hertz_scaling_symmetry(tol, peak_of):
    """Eq. 1 without dissipation is invariant under u -> a^4 u, t -> t / a, v -> a^5 v:
    forces scale as V0^(6/5) and times as V0^(-1/5). With dt scaled the same way the two
    runs are one run in scaled units, equal to round-off."""
    model = uniform_chain(20)
    slow, fast = 0.1, 0.4
    time_scale = (fast / slow) ** -0.2
    force_scale = (fast / slow) ** 1.2
    dt = default_time_step(model, slow)
    runs = [
        simulate(model, v, v, duration=1e-3 * s, dt=dt * s, record_interval=10 * dt * s)
        for v, s in ((slow, 1.0), (fast, time_scale))
    ]
    np.testing.assert_allclose(runs[1].time, runs[0].time * time_scale, rtol=tol.roundoff)
    reference = runs[0].contact_force[0]
    scaled = runs[1].contact_force[0] / force_scale
    np.testing.assert_allclose(scaled, reference, rtol=0, atol=tol.scaling * reference.max())
    # The same at one contact, as a lab would measure it: peak force and arrival time.
    t_slow, f_slow = peak_of(runs[0].time, runs[0].contact(5)[0])
    t_fast, f_fast = peak_of(runs[1].time, runs[1].contact(5)[0])
    assert f_fast / f_slow == pytest.approx(force_scale, rel=tol.scaling)
    assert t_fast / t_slow == pytest.approx(time_scale, rel=tol.scaling)


# --------------------------------------------------------------------------- sensor beads


def test_sensor_bead_reads_the_felt_force(tol, peak_of):
    """A bead cut in two around a PCB 200B02 (1.9e9 N/m) reads, at its peak, the mean of
    its two contact forces in an unsplit chain (F_{n-1,n} + F_{n,n+1}) / 2 within 1 %,
    and at the same time within 2 % of the pulse duration; the split bead barely
    disturbs the wave."""
    speeds = [0.02, 0.1, 1.0]
    kwargs = {"duration": 1.5e-3, "record_interval": 1e-7}
    split = simulate(uniform_chain(26, sensor_beads=[10, 17]), speeds, 0.0, **kwargs)
    whole = simulate(uniform_chain(26), speeds, 0.0, **kwargs)
    for launch in range(len(speeds)):
        for bead in (10, 17):
            felt = whole.force_felt(bead)[launch]
            t_sensor, f_sensor = peak_of(split.time, split.sensor(bead)[launch])
            t_felt, f_felt = peak_of(whole.time, felt)
            duration = felt.sum() * (whole.time[1] - whole.time[0]) / f_felt
            assert f_sensor == pytest.approx(f_felt, rel=tol.sensor_peak)
            assert abs(t_sensor - t_felt) <= tol.sensor_arrival_fraction * duration


# --------------------------------------------------------------------------- input checks


@pytest.mark.parametrize(
    ("kwargs", "parameter"),
    [
        ({"dt": 0.0}, "dt"),
        ({"dt": -1e-8}, "dt"),
        ({"duration": 0.0}, "duration"),
        ({"duration": -2.6e-3}, "duration"),
        ({"record_interval": 0.0}, "record_interval"),
        ({"v_left": -0.1}, "v_left"),
        ({"v_right": -0.1}, "v_right"),
        ({"v_left": math.inf}, "v_left"),
        ({"v_left": 0.0, "v_right": 0.0}, "v_left or v_right"),
    ],
)
def test_simulate_rejects_invalid_input(kwargs, parameter):
    """simulate names the bad parameter before integrating anything."""
    arguments = {"v_left": 0.1, "v_right": 0.1, "duration": 1e-4}
    arguments.update(kwargs)
    with pytest.raises(ParameterError, match=parameter):
        simulate(uniform_chain(4), **arguments)


def test_readers_reject_bad_indices():
    """Contacts are 1..N-1, beads 1..N, sensors only where the model has them."""
    result = simulate(uniform_chain(4), 0.1, 0.0, duration=1e-5)
    with pytest.raises(ParameterError, match="contact"):
        result.contact(4)
    with pytest.raises(ParameterError, match="bead"):
        result.force_felt(5)
    with pytest.raises(ParameterError, match="not a sensor bead"):
        result.sensor(2)


# --------------------------------------------------------------------------- what is recorded


def test_a_long_chain_records_an_overview_by_default(monkeypatch):
    """Beyond OVERVIEW_CONTACTS contacts the default record is every stride-th contact
    and bead, the last ones and the sensors' (so every sensor bead's felt force reads),
    each column bit-identical to the same column of contacts="all"; a contact outside
    the overview is refused with the keyword to ask for it."""
    from chain.physics import record

    monkeypatch.setattr(record, "OVERVIEW_CONTACTS", 8)
    model = uniform_chain(40)
    kwargs = {"duration": 2e-4, "record_interval": 2e-6}
    overview = simulate(model, 0.3, 0.3, **kwargs)
    full = simulate(model, 0.3, 0.3, contacts="all", beads="all", **kwargs)
    stride = math.ceil(39 / 8)
    assert overview.contacts == (*range(1, 40, stride), 39)
    assert overview.beads == (*range(1, 41, stride), 40)
    assert full.contacts is None and full.beads is None
    for k in overview.contacts:
        assert np.array_equal(overview.contact(k), full.contact(k))
    for n in overview.beads:
        assert np.array_equal(overview.velocity(n), full.velocity(n))
    with pytest.raises(ParameterError, match="contacts="):
        overview.contact(2)
    sensed = uniform_chain(40, sensor_beads=(13, 27))
    with_sensors = simulate(sensed, 0.3, 0.3, **kwargs)
    every = simulate(sensed, 0.3, 0.3, contacts="all", **kwargs)
    assert {12, 13, 26, 27} <= set(with_sensors.contacts)
    assert {13, 27} <= set(with_sensors.beads)
    for bead in (13, 27):
        assert np.array_equal(with_sensors.force_felt(bead), every.force_felt(bead))
    short = simulate(uniform_chain(9), 0.3, 0.3, **kwargs)
    assert short.contacts is None and short.contact_force.shape[2] == 8


def test_a_large_record_warns_and_says_how_to_record_less(monkeypatch):
    """A record over RECORD_WARNING_BYTES warns (LargeRecordWarning) with the keywords
    that choose less; a selection under it runs silently."""
    import warnings

    from chain.physics import record

    model = uniform_chain(20)
    kwargs = {"duration": 1e-4, "record_interval": 1e-6}
    # 101 samples x (19 contacts + 2 x 20 bead velocities) x 8 bytes = 47.7 kB.
    monkeypatch.setattr(record, "RECORD_WARNING_BYTES", 40e3)
    with pytest.warns(record.LargeRecordWarning, match=r"contacts=.*beads=\(\)"):
        simulate(model, 0.3, 0.3, contacts="all", **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        simulate(model, 0.3, 0.3, contacts=range(1, 20, 4), beads=(), **kwargs)
    with pytest.raises(ParameterError, match="contacts"):
        simulate(model, 0.3, 0.3, contacts="every", **kwargs)
