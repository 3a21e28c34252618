"""The lean kernel (chain.physics.kernels) against the general reference kernel.

The lean kernel does the general kernel's arithmetic in the same order with less
bookkeeping, so every model must give the same bits: records, final state and the
number of steps refined at contact events. Launches run on threads; the result of a
launch must not depend on the thread count or on the other launches of the batch.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from chain.physics.builders import uniform_chain
from chain.physics.integrator import integrate
from chain.physics.model import launch_velocities
from chain.physics.simulation import default_time_step

#: The kernels these tests run, compiled in turns by the workers (conftest.py).
pytestmark = pytest.mark.usefixtures("unit_test_kernels")

FIELDS = (
    "link_force",
    "wall_force",
    "velocity",
    "energy",
    "momentum",
    "final_displacement",
    "final_velocity",
    "refined_steps",
)

#: Every fast path of the lean kernel: plain Hertz (no walls, springs or drag),
#: Kuwabara-Kono, sensor springs with walls, strikers with track friction.
MODELS = {
    "elastic": lambda: uniform_chain(26),
    "kuwabara-kono": lambda: uniform_chain(26, eta=0.58e-6),
    "sensors+walls": lambda: uniform_chain(
        12, eta=0.58e-6, sensor_beads=[4, 9], left_wall=True, right_wall=True
    ),
    "strikers+drag": lambda: uniform_chain(
        10, eta=0.58e-6, sensor_beads=[3], striker_radius=4e-3, drag_rate=30.0
    ),
}


def _run(model, kernel, **kwargs):
    velocity = launch_velocities(model, [0.3, 1.0], [0.3, 0.0])
    dt = default_time_step(model, 1.0)
    return integrate(model, velocity, 1e-3, dt, record_every=7, kernel=kernel, **kwargs)


@pytest.mark.parametrize("name", MODELS)
def test_lean_kernel_is_bit_identical_to_the_reference(name):
    """Same records, same final state, same refined steps, to the last bit, and the
    contact-event refinement did happen (so it was compared too)."""
    model = MODELS[name]()
    lean = _run(model, "lean")
    reference = _run(model, "reference")
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(lean, field), getattr(reference, field), field)
    assert np.all(lean.refined_steps > 0)


def test_recording_a_selection_gives_the_same_numbers():
    """Recording chosen links and particles gives exactly the columns of a full record."""
    model = MODELS["sensors+walls"]()
    links, particles = [2, 4, 10], [0, 5]
    full = _run(model, "lean")
    part = _run(model, "lean", links=links, particles=particles)
    np.testing.assert_array_equal(part.link_force, full.link_force[:, :, links])
    np.testing.assert_array_equal(part.velocity, full.velocity[:, :, particles])
    np.testing.assert_array_equal(part.energy, full.energy)


def test_batch_is_identical_on_one_thread_and_on_all():
    """An amplitude sweep in one call gives the same bits with 1 thread and with all,
    and each launch the same bits as when integrated alone."""
    model = uniform_chain(20, eta=0.58e-6)
    speeds = np.geomspace(0.02, 1.0, 6)
    velocity = launch_velocities(model, speeds, speeds)
    dt = default_time_step(model, 1.0)
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        serial = integrate(model, velocity, 5e-4, dt, record_every=10)
    finally:
        numba.set_num_threads(threads)
    parallel = integrate(model, velocity, 5e-4, dt, record_every=10)
    alone = integrate(model, velocity[3], 5e-4, dt, record_every=10)
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(parallel, field), getattr(serial, field), field)
    np.testing.assert_array_equal(parallel.link_force[3], alone.link_force[0])


def test_simulate_records_only_what_is_asked():
    """simulate(contacts=, beads=) returns exactly the matching columns of a full run;
    the bead velocities equal the per-bead loop of mass-weighted means, bit for bit
    (sensor halves included); an unrecorded contact is refused by name."""
    from chain.errors import ParameterError
    from chain.physics.simulation import simulate

    model = uniform_chain(12, eta=0.58e-6, sensor_beads=[4, 9], striker_radius=4e-3)
    kwargs = {"duration": 3e-4, "record_interval": 2e-6}
    full = simulate(model, [0.2, 0.5], [0.2, 0.0], **kwargs)
    part = simulate(model, [0.2, 0.5], [0.2, 0.0], contacts=[3, 4], beads=[4, 5], **kwargs)
    raw = integrate(
        model,
        launch_velocities(model, [0.2, 0.5], [0.2, 0.0]),
        3e-4,
        full.dt,
        record_every=round(2e-6 / full.dt),
    )
    masses = model.masses
    loop = np.stack(
        [
            (raw.velocity[:, :, a : b + 1] * masses[a : b + 1]).sum(axis=2)
            / masses[a : b + 1].sum()
            for a, b in zip(model.bead_first, model.bead_last)
        ],
        axis=2,
    )
    np.testing.assert_array_equal(full.bead_velocity, loop)
    np.testing.assert_array_equal(part.force_felt(4), full.force_felt(4))
    np.testing.assert_array_equal(part.sensor(9), full.sensor(9))
    np.testing.assert_array_equal(part.velocity(5), full.velocity(5))
    np.testing.assert_array_equal(part.end_force, full.end_force)
    assert part.contact_force.shape[2] == 2 and part.bead_velocity.shape[2] == 2
    with pytest.raises(ParameterError, match="contact 7 was not recorded"):
        part.contact(7)


@pytest.mark.parametrize("threads", [1, 2])
def test_a_sweep_in_one_pool_gives_the_bits_of_separate_calls(threads):
    """simulate_many (every launch of several chains in one thread pool, longest
    first) gives each run the bits of its own simulate call, on one thread or two;
    shared arguments apply to every run, a run's own win; unknown names are refused."""
    from chain.errors import ParameterError
    from chain.physics.integrator import integrate_many
    from chain.physics.simulation import simulate, simulate_many

    runs = [
        {"model": MODELS[name](), "v_left": [0.3, 0.05], "v_right": [0.3, 0.0]} for name in MODELS
    ]
    runs[1]["duration"] = 2e-4
    together = simulate_many(runs, threads=threads, duration=3e-4, record_interval=2e-6)
    for run, result in zip(runs, together, strict=True):
        alone = simulate(**{"duration": 3e-4, "record_interval": 2e-6, **run})
        for field in ("time", "contact_force", "end_force", "bead_velocity", "sensor_force"):
            np.testing.assert_array_equal(getattr(result, field), getattr(alone, field), field)
        np.testing.assert_array_equal(result.total_energy, alone.total_energy)
    assert together[1].time[-1] == pytest.approx(2e-4)
    with pytest.raises(ParameterError, match="unknown"):
        simulate_many([{**runs[0], "speed": 1.0}])
    model = MODELS["elastic"]()
    with pytest.raises(ParameterError, match="lean"):
        integrate_many(
            [
                dict(
                    model=model,
                    initial_velocity=launch_velocities(model, 0.1),
                    duration=1e-5,
                    dt=1e-7,
                    kernel="reference",
                )
            ]
        )


#: Long chains whose middle the lean kernel skips until the waves come near it, and
#: whether they come near it within the test's 4 ms (track friction slows them).
LONG_MODELS = {
    "elastic": (lambda: uniform_chain(420), True),
    "sensors+walls+damping": (
        lambda: uniform_chain(
            400, eta=0.58e-6, sensor_beads=[150, 200, 330], left_wall=True, right_wall=True
        ),
        True,
    ),
    "strikers+drag": (
        lambda: uniform_chain(
            380, eta=0.58e-6, sensor_beads=[190], striker_radius=4e-3, drag_rate=30.0
        ),
        False,
    ),
}


@pytest.mark.parametrize("name", LONG_MODELS)
def test_skipping_beads_at_rest_gives_the_reference_bits(name, monkeypatch):
    """A long chain's middle, at rest, is skipped (chain.physics.at_rest) and the
    skipped part shrinks as the waves approach: same bits as the reference kernel,
    which integrates every bead at every step; a launch from one end and one from
    both ends; records chosen in and out of the skipped part."""
    from chain.physics import at_rest

    parts = []
    real = at_rest._integrate_part

    def counted(*args):
        parts.append(args[0].shape[0])
        return real(*args)

    monkeypatch.setattr(at_rest, "_integrate_part", counted)
    factory, shrinks = LONG_MODELS[name]
    model = factory()
    velocity = launch_velocities(model, [1.0, 0.5], [1.0, 0.0])
    dt = default_time_step(model, 1.0)
    links = [0, 5, 140, 200, 260, model.n_particles - 2]
    particles = [0, 100, 210, model.n_particles - 1]
    kwargs = dict(record_every=25, links=links, particles=particles)
    lean = integrate(model, velocity, 4e-3, dt, **kwargs)
    reference = integrate(model, velocity, 4e-3, dt, kernel="reference", **kwargs)
    for field in FIELDS:
        np.testing.assert_array_equal(getattr(lean, field), getattr(reference, field), field)
    assert min(parts) <= model.n_particles - at_rest.MIN_SKIPPED  # the middle was skipped
    # and, where the waves came near it, the skipped part shrank: a launch ran in parts
    assert (len(parts) > 2) == shrinks
    assert np.all(lean.refined_steps > 0)


def test_a_long_chain_runs_the_kernel_a_short_chain_compiled(cold_step_loop_jobs):
    """numba compiles the step loop (kernels._integrate_part) once per kind of model:
    the whole chain (_integrate_one) and chain.physics.at_rest call it from Python with
    the same types, never with literal constants, for which numba would compile the
    whole loop again (~13 s of a cold run, per kind); and the loop records every sample,
    the first one included, through one compiled _record (a literal 0 compiled it
    twice). Read off the job of conftest.py's :func:`cold_step_loop_jobs` that compiled
    the loop, cold, in a fresh interpreter with an empty numba cache (~20 s; run once
    for this test and one of tests/test_compile_once.py): with the kernels in numba's
    cache the callee's signatures are not recorded, and the test would compare nothing.
    It simulated a short chain (the whole chain), then a 400-bead one launched from one
    end only, whose far beads at rest are skipped (at_rest)."""
    reports, _ = cold_step_loop_jobs
    compiled = [report for report in reports if report["misses"]]
    assert compiled, reports  # one job compiled the loop (tests/test_compile_once.py)
    whole, after_at_rest, records = (compiled[0][k] for k in ("whole", "after_at_rest", "records"))
    assert len(whole) == 1, whole  # the whole chain compiled the loop once
    assert after_at_rest == whole
    assert "Literal" not in whole[0], whole
    assert len(records) == 1, records
