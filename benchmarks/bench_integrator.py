"""Benchmark of the simulation core: numba RK4 against scipy's DOP853 at equal accuracy.

Run from the repository root (after ``pip install -e .``)::

    python benchmarks/bench_integrator.py

It prints, for the paper's hardest conservative run (N = 26, collision at V0 = 1 m/s,
2.6 ms simulated):

1. the numba fixed-step RK4 with the default step (``chain.simulate(dt=None)``): wall
   time after compilation and the relative energy drift it achieves;
2. scipy ``solve_ivp(method="DOP853")`` on a plain-numpy right-hand side of the same
   equations, at the loosest tolerance that still gives an energy drift <= 1e-9;
3. a 16-amplitude batch (V0 geometric from 0.02 to 1 m/s, collisions) in one
   ``simulate`` call after compilation, with steps and ns per particle-step;
4. diagnostics of where the time goes: the energy drift against the number of steps
   per contact time (the delta^(3/2) kink makes RK4 converge like dt^2.5 only), and a
   minimal RK4 kernel for the same chain (no dissipation, walls, sensors or recording)
   as a floor for the cost of one particle-step.

Timings are the best of ``--repeat`` runs (other work on the machine only slows runs
down). Not a test: it asserts nothing, it reports. The figures measured on the project
machine are in ``benchmarks/README.md``.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numba
import numpy as np
import scipy
from scipy.integrate import solve_ivp

import chain
from chain import (
    STEEL_100C6,
    contact_stiffness,
    default_time_step,
    simulate,
    sphere_mass,
    uniform_chain,
)
from chain.physics.simulation import STEPS_PER_CONTACT_TIME

N_BEADS = 26
DURATION = 2.6e-3  # s, the paper's run
RECORD_INTERVAL = 1e-6  # s, the library's default
SPEED = 1.0  # m/s, fastest launch of the paper's sweep
BATCH_SPEEDS = np.geomspace(0.02, 1.0, 16)  # m/s
TARGET_DRIFT = 1e-9
RADIUS = 13e-3  # m


def best_time(function, repeat: int):
    """(best wall time in s, last result) of ``repeat`` calls of ``function``."""
    best = math.inf
    result = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def numpy_chain(n_beads: int):
    """Right-hand side and energy of Eq. 1 (free ends, equal beads) in plain numpy."""
    mass = sphere_mass(STEEL_100C6, RADIUS)
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)

    def rhs(_t, y):
        overlap = np.maximum(y[: n_beads - 1] - y[1:n_beads], 0.0)
        force = kappa * overlap * np.sqrt(overlap)
        acceleration = np.zeros(n_beads)
        acceleration[:-1] -= force
        acceleration[1:] += force
        return np.concatenate([y[n_beads:], acceleration / mass])

    def energy(y):
        overlap = np.maximum(y[: n_beads - 1] - y[1:n_beads], 0.0)
        return 0.5 * mass * np.sum(y[n_beads:] ** 2, axis=0) + 0.4 * kappa * np.sum(
            overlap**2.5, axis=0
        )

    return rhs, energy


def run_dop853(rtol: float):
    """One DOP853 run of the benchmark collision; returns (energy drift, n_rhs_calls)."""
    rhs, energy = numpy_chain(N_BEADS)
    y0 = np.zeros(2 * N_BEADS)
    y0[N_BEADS] = SPEED
    y0[-1] = -SPEED
    # Absolute tolerances on the scale of the state: overlaps ~ 1e-5 m, speeds ~ V0.
    atol = np.r_[np.full(N_BEADS, 1e-5 * rtol), np.full(N_BEADS, SPEED * rtol)] * 1e-3
    samples = np.arange(0.0, DURATION + RECORD_INTERVAL / 2, RECORD_INTERVAL)
    solution = solve_ivp(
        rhs, (0.0, DURATION), y0, method="DOP853", rtol=rtol, atol=atol, t_eval=samples
    )
    if not solution.success:
        raise RuntimeError(solution.message)
    total = energy(solution.y)
    return float(np.max(np.abs(total - total[0])) / total[0]), solution.nfev


@numba.njit(cache=True)
def _minimal_derivatives(u, inverse_mass, kappa, acc):
    previous = 0.0
    for j in range(u.shape[0] - 1):
        overlap = u[j] - u[j + 1]
        force = kappa * overlap * math.sqrt(overlap) if overlap > 0.0 else 0.0
        acc[j] = (previous - force) * inverse_mass
        previous = force
    acc[u.shape[0] - 1] = previous * inverse_mass


@numba.njit(cache=True)
def _minimal_rk4(u, v, inverse_mass, kappa, dt, n_steps):
    # Classical RK4 for N equal beads, free ends, eta = 0, nothing recorded.
    n = u.shape[0]
    acc = np.empty(n)
    u_stage = np.empty(n)
    v_stage = np.empty(n)
    u_sum = np.empty(n)
    v_sum = np.empty(n)
    for _ in range(n_steps):
        u_stage[:] = u
        v_stage[:] = v
        u_sum[:] = 0.0
        v_sum[:] = 0.0
        for stage in range(4):
            _minimal_derivatives(u_stage, inverse_mass, kappa, acc)
            weight = 1.0 if stage == 0 or stage == 3 else 2.0
            h = dt if stage == 2 else 0.5 * dt
            for p in range(n):
                u_sum[p] += weight * v_stage[p]
                v_sum[p] += weight * acc[p]
                if stage < 3:
                    u_stage[p] = u[p] + h * v_stage[p]
                    v_stage[p] = v[p] + h * acc[p]
        for p in range(n):
            u[p] += dt / 6.0 * u_sum[p]
            v[p] += dt / 6.0 * v_sum[p]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed runs, best kept")
    args = parser.parse_args()

    print("== machine")
    print(f"cpu: {platform.processor() or platform.machine()}, {os.cpu_count()} cores")
    print(f"numba threads: {numba.get_num_threads()}")
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}"
        f", numba {numba.__version__}, chain {chain.__version__}"
    )

    model = uniform_chain(N_BEADS)

    def one_collision():
        return simulate(model, SPEED, SPEED, duration=DURATION, record_interval=RECORD_INTERVAL)

    start = time.perf_counter()
    one_collision()
    first_call = time.perf_counter() - start
    rk4_time, result = best_time(one_collision, args.repeat)
    steps = math.ceil(DURATION / result.dt - 1e-9)
    print(f"\n== numba RK4, one collision: N = {N_BEADS}, V0 = {SPEED} m/s, {DURATION * 1e3} ms")
    print(f"first call (compile or cache load + run): {first_call:.3f} s")
    print(f"dt = {result.dt:.4e} s (default), steps = {steps}")
    print(f"energy drift = {result.energy_drift[0]:.2e} (target <= {TARGET_DRIFT:.0e})")
    print(f"wall time = {rk4_time * 1e3:.1f} ms")
    print(f"  = {rk4_time / (steps * N_BEADS) * 1e9:.1f} ns per particle-step (one thread)")

    print("\n== scipy solve_ivp DOP853, numpy right-hand side, same run")
    chosen = None
    for rtol in (1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 3e-12, 1e-12, 3e-13, 1e-13):
        drift, calls = run_dop853(rtol)
        print(f"rtol = {rtol:.0e}: energy drift = {drift:.2e}, rhs calls = {calls}")
        if drift <= TARGET_DRIFT:
            chosen = rtol
            break
    if chosen is None:
        raise SystemExit("DOP853 never reached the target drift")
    dop_time, (drift, calls) = best_time(lambda: run_dop853(chosen), args.repeat)
    print(f"loosest rtol with drift <= {TARGET_DRIFT:.0e}: {chosen:.0e} (atol scaled alike)")
    print(f"wall time = {dop_time * 1e3:.1f} ms, energy drift = {drift:.2e}")
    print(f"\nspeedup numba RK4 / DOP853 = {dop_time / rk4_time:.1f}x (target >= 20x)")

    def batch():
        return simulate(
            model, BATCH_SPEEDS, BATCH_SPEEDS, duration=DURATION, record_interval=RECORD_INTERVAL
        )

    batch()  # compiled already; one untimed call to settle the thread pool
    batch_time, batch_result = best_time(batch, args.repeat)
    steps = math.ceil(DURATION / batch_result.dt - 1e-9)
    particle_steps = steps * N_BEADS * len(BATCH_SPEEDS)
    threads = numba.get_num_threads()
    print(f"\n== batch: {len(BATCH_SPEEDS)} collisions, V0 = 0.02..1 m/s (geometric), one call")
    print(f"dt = {batch_result.dt:.4e} s (set by the fastest launch), steps = {steps}")
    print(f"max energy drift = {batch_result.energy_drift.max():.2e}")
    print(f"wall time = {batch_time:.3f} s (target: well under 1 s)")
    print(
        f"  = {batch_time / particle_steps * 1e9:.1f} ns wall, "
        f"{batch_time * threads / particle_steps * 1e9:.1f} ns CPU per particle-step "
        f"({particle_steps / 1e6:.1f} M particle-steps, {threads} threads)"
    )
    # What a per-launch default step would save (each amplitude at its own dt ~ V0^-1/5).
    own_steps = sum(math.ceil(DURATION / (result.dt * (v / SPEED) ** -0.2)) for v in BATCH_SPEEDS)
    print(
        f"  steps if every launch used its own default step: {own_steps} "
        f"({own_steps / (steps * len(BATCH_SPEEDS)):.2f} of the shared-step total)"
    )

    print("\n== where the time goes")
    base = default_time_step(model, SPEED)
    for factor in (1.0, 1.5, 3.0):
        run = simulate(
            model,
            SPEED,
            SPEED,
            duration=DURATION,
            dt=base * factor,
            record_interval=RECORD_INTERVAL,
            max_energy_drift=math.inf,
        )
        print(
            f"{STEPS_PER_CONTACT_TIME / factor:6.0f} steps per contact time: "
            f"energy drift = {run.energy_drift[0]:.2e}"
        )
    mass = sphere_mass(STEEL_100C6, RADIUS)
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    u = np.zeros(N_BEADS)
    v = np.zeros(N_BEADS)
    _minimal_rk4(u.copy(), v.copy(), 1.0 / mass, kappa, result.dt, 10)  # compile
    v[0], v[-1] = SPEED, -SPEED
    minimal_steps = math.ceil(DURATION / result.dt - 1e-9)
    minimal_time, _ = best_time(
        lambda: _minimal_rk4(u.copy(), v.copy(), 1.0 / mass, kappa, result.dt, minimal_steps),
        args.repeat,
    )
    print(
        f"minimal RK4 kernel, same run: {minimal_time * 1e3:.1f} ms = "
        f"{minimal_time / (minimal_steps * N_BEADS) * 1e9:.1f} ns per particle-step "
        f"(library kernel: {rk4_time / (minimal_steps * N_BEADS) * 1e9:.1f} ns)"
    )
    print(
        f"rhs evaluations: RK4 {4 * minimal_steps}, DOP853 {calls} "
        f"({4 * minimal_steps / calls:.0f}x more for RK4)"
    )


if __name__ == "__main__":
    main()
