"""What a simulation job asks a batch scheduler for: memory (MB) and run time (minutes).

A SLURM job is killed when it passes its request, and waits longer the more it asks.

Memory: the integrator keeps every recorded sample of every particle of a batch of B
launches. The simulate script's peak, measured for N = 16..100, 4..24 launch speeds and
1.5..5.2 ms, is 200 MB + (48 N + 80) bytes x B x S (S samples) within 10 MB; with an
empty numba cache, compiling the kernels peaks at ~590 MB first: the request's base.

Run time: RK4 costs at most :data:`SECONDS_PER_PARTICLE_STEP` per particle and step on
one core; a job runs 2 B launches of duration / dt steps. Every paper job asks for
:data:`MIN_RUNTIME_MIN`; the estimate matters for long sweeps (N = 100, 5 ms, 24 speeds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from chain.errors import require_int, require_positive
from chain.physics.model import ChainModel
from chain.physics.time_step import default_time_step

#: Resident memory of the simulate script before it allocates traces, MB: the numba
#: compilation peak with an empty cache (measured 590 MB; 200 MB with a warm cache).
BASE_MB = 600.0
#: Bytes held per launch and recorded sample: per bead (six float64, measured 47-48),
#: and besides the beads (trace table rows).
BYTES_PER_BEAD_SAMPLE = 48.0
BYTES_PER_SAMPLE = 80.0
#: Resident memory of the Snakemake process that runs the script inside the job, MB.
SNAKEMAKE_MB = 200.0
#: Factor between the estimate and the request (memory and time).
SAFETY = 1.5
#: RK4 cost per particle and time step on one core, s (measured 2e-8 to 6e-8, loaded).
SECONDS_PER_PARTICLE_STEP = 1e-7
#: Python start-up, imports and file writing of one job, s; shortest request, minutes.
STARTUP_S = 60.0
MIN_RUNTIME_MIN = 10
#: Estimated single-core integration a job needs before a second core pays, s: only
#: the integration runs in parallel, and a core held idle by a small job is a core
#: another job cannot use. At most :data:`MAX_THREADS` threads.
SECONDS_PER_THREAD = 10.0
MAX_THREADS = 8


@dataclass(frozen=True)
class JobNeeds:
    """A job's request: ``mem_mb`` (MB) and ``runtime`` (minutes), Snakemake's names."""

    mem_mb: int
    runtime: int


def _integration_seconds(
    model: ChainModel, n_launches: int, max_launch_speed: float, duration: float, dt
) -> float:
    """Estimated single-core RK4 time of 2 ``n_launches`` launches, s (the bound
    :data:`SECONDS_PER_PARTICLE_STEP`)."""
    if dt is None:
        dt = default_time_step(model, require_positive("max_launch_speed", max_launch_speed))
    return 2 * n_launches * model.n_particles * (duration / dt) * SECONDS_PER_PARTICLE_STEP


def simulation_threads(
    model: ChainModel,
    n_launches: int,
    max_launch_speed: float,
    duration: float,
    dt: float | None = None,
) -> int:
    """Cores worth giving a simulate job (the paper's chains: 1; N = 100, 24 speeds,
    5.2 ms: 4): one per :data:`SECONDS_PER_THREAD` of estimated integration, at least 1,
    at most the 2 ``n_launches`` launches (collision and reference shots share one
    thread pool) and :data:`MAX_THREADS`. Each launch runs on one thread: the results
    do not depend on the count. Parameters as :func:`simulation_needs` (m/s, s).
    """
    n_launches = require_int("n_launches", n_launches, 1)
    duration = require_positive("duration", duration)
    work = _integration_seconds(model, n_launches, max_launch_speed, duration, dt)
    return max(1, min(2 * n_launches, MAX_THREADS, math.ceil(work / SECONDS_PER_THREAD)))


def simulation_needs(
    model: ChainModel,
    n_launches: int,
    max_launch_speed: float,
    duration: float,
    record_interval: float,
    dt: float | None = None,
    threads: int = 1,
) -> JobNeeds:
    """Memory (``mem_mb``, MB, a multiple of 100) and run time (``runtime``, minutes) to
    ask for a simulate job (collision and reference batches).

    Parameters
    ----------
    model : ChainModel
        The chain simulated.
    n_launches : int
        Launch speeds B; each gives a collision and a reference shot.
    max_launch_speed : float
        Fastest launch speed, m/s (sets the default time step).
    duration : float
        Simulated time, s.
    record_interval : float
        Time between recorded samples, s.
    dt : float, optional
        RK4 step, s; default :func:`chain.physics.time_step.default_time_step`.
    threads : int
        Cores the job gets (launches run in parallel threads).
    """
    n_launches = require_int("n_launches", n_launches, 1)
    threads = require_int("threads", threads, 1)
    duration = require_positive("duration", duration)
    record_interval = require_positive("record_interval", record_interval)
    samples = duration / record_interval + 1
    held = (BYTES_PER_BEAD_SAMPLE * model.n_particles + BYTES_PER_SAMPLE) * n_launches * samples
    memory = SAFETY * (BASE_MB + SNAKEMAKE_MB + held / 1e6)
    work = _integration_seconds(model, n_launches, max_launch_speed, duration, dt)
    seconds = SAFETY * (STARTUP_S + work / min(threads, 2 * n_launches))
    return JobNeeds(
        mem_mb=int(100 * math.ceil(memory / 100)),
        runtime=max(MIN_RUNTIME_MIN, math.ceil(seconds / 60)),
    )
