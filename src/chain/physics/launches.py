"""One batch's launches on the lean or the reference RK4 kernel: the model as the
kernel's flat arrays, the zeroed records, and one task per launch.

:func:`chain.physics.integrator.integrate` checks a run's inputs and turns a failed run
into an error; this module only lays a checked batch out for a kernel and runs its tasks.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache, partial

import numpy as np

from chain.physics import reference_kernel
from chain.physics.at_rest import integrate_launch
from chain.physics.model import HERTZ, SPRING, ChainModel

#: Fixed seed of the 64-bit keys that fingerprint the set of closed contacts.
_KEY_SEED = 20141117


def _outputs(batch: int, n_samples: int, n_links: int, n_particles: int):
    """Zeroed (link force, wall force, velocity, energy, momentum) records."""
    return (
        np.zeros((batch, n_samples, n_links)),
        np.zeros((batch, n_samples, 2)),
        np.zeros((batch, n_samples, n_particles)),
        np.zeros((batch, n_samples, 3)),
        np.zeros((batch, n_samples)),
    )


def _report(batch: int):
    """(status, failing step, refined steps) per launch."""
    return tuple(np.zeros(batch, dtype=np.int64) for _ in range(3))


@lru_cache(maxsize=256)
def _contact_keys(n_links: int) -> np.ndarray:
    """One fixed random 64-bit key per link and per wall (read-only), so that runs are
    reproducible; drawn once per chain length (a quarter of a short run's set-up)."""
    keys = np.random.default_rng(_KEY_SEED).integers(
        0, np.iinfo(np.uint64).max, size=n_links + 2, dtype=np.uint64, endpoint=True
    )
    keys.flags.writeable = False
    return keys


def _lean_params(model: ChainModel) -> tuple:
    """The model as the flat arrays of :mod:`chain.physics.kernels` (see ``_slopes``)."""
    kind = np.ascontiguousarray(model.link_kind, dtype=np.int64)
    damping = 1.5 * model.link_eta * model.link_stiffness
    damping[kind == SPRING] = 0.0
    n_links = model.n_particles - 1
    # A copy: the kernels take writable arrays (a read-only one is another signature).
    keys = _contact_keys(n_links).copy()
    springs = np.append(np.flatnonzero(kind == SPRING), n_links).astype(np.int64)
    walls = np.stack([model.wall_stiffness, 1.5 * model.wall_eta * model.wall_stiffness], axis=1)
    drag = np.stack([model.drag_rate, model.masses * model.drag_rate], axis=1)
    # None when absent, so that numba compiles a kernel without them.
    # (array.any(): numpy's np.any wrapper costs more than the test on a short chain)
    walls = tuple(map(float, walls.ravel())) if (model.wall_stiffness > 0).any() else None
    drag = np.ascontiguousarray(drag) if (model.drag_rate > 0).any() else None
    damped = damping if (damping[kind == HERTZ] > 0).any() else None
    return (
        1.0 / model.masses,
        np.ascontiguousarray(model.masses, dtype=float),
        np.ascontiguousarray(model.link_stiffness, dtype=float),
        damping,
        keys,
        springs,
        walls,
        drag,
        kind,
        damped,
    )


def _lean_launches(model: ChainModel, run, n_samples: int, links, particles):
    """(outputs, report, launches) of a batch for the lean kernel."""
    displacement, velocity, dt, n_steps, record_every = run
    batch = velocity.shape[0]
    outputs = _outputs(batch, n_samples, len(links), len(particles))
    status, fail_step, refined = report = _report(batch)
    params = _lean_params(model)

    def launch(b: int) -> None:
        one = tuple(out[b] for out in outputs)
        result = integrate_launch(
            displacement[b], velocity[b], params, dt, n_steps, record_every, links, particles, one
        )
        status[b], fail_step[b], refined[b] = result

    cost = n_steps * model.n_particles
    return outputs, report, [(cost, partial(launch, b)) for b in range(batch)]


def _run_launches(launches: list, threads: int) -> None:
    """Run (cost, function) tasks, on ``threads`` threads when there are several.

    Launches are independent and the kernel releases the GIL: each launch runs on one
    thread, so the results do not depend on the thread count. The longest go first, so
    that no thread is left with a long launch at the end of a sweep."""
    workers = min(len(launches), threads)
    if workers <= 1:
        for _, function in launches:
            function()
        return
    ordered = sorted(launches, key=lambda task: -task[0])
    with ThreadPoolExecutor(max_workers=workers) as pool:
        list(pool.map(lambda task: task[1](), ordered))


def _reference_launches(model: ChainModel, run, n_samples: int, links, particles):
    """(outputs, report, launches) of a batch for the reference kernel: one task that
    runs the whole batch, then keeps the recorded links and particles."""
    displacement, velocity, dt, n_steps, record_every = run
    n_particles = model.n_particles
    full = _outputs(velocity.shape[0], n_samples, max(n_particles - 1, 1), n_particles)
    report = _report(velocity.shape[0])
    link_damping = 1.5 * model.link_eta * model.link_stiffness
    link_damping[model.link_kind == SPRING] = 0.0
    params = (
        np.ascontiguousarray(model.masses, dtype=float),
        1.0 / model.masses,
        np.ascontiguousarray(model.link_kind, dtype=np.int64),
        np.ascontiguousarray(model.link_stiffness, dtype=float),
        link_damping,
        np.ascontiguousarray(model.wall_stiffness, dtype=float),
        1.5 * model.wall_eta * model.wall_stiffness,
        np.ascontiguousarray(model.drag_rate, dtype=float),
        bool(np.any(model.drag_rate > 0)),
    )
    outputs = [None] * 5

    def launch() -> None:
        reference_kernel._integrate_batch(
            displacement, velocity, params, dt, n_steps, record_every, *full, *report,
        )  # fmt: skip
        link_force, wall_force, recorded_velocity, energy, momentum = full
        outputs[:] = (
            link_force[:, :, links],
            wall_force,
            recorded_velocity[:, :, particles],
            energy,
            momentum,
        )

    # ``outputs`` is filled in place when the task runs.
    return outputs, report, [(n_steps * n_particles, launch)]
