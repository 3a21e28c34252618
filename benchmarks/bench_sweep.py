"""Throughput of a what-if sweep (many N x V0) against C, per core and on all cores.

Run from the repository root::

    python benchmarks/bench_sweep.py                   # 1,000 collisions, best of 7
    python benchmarks/bench_sweep.py --collisions 200 --duration 0.5e-3   # a quick look

The sweep: ``--chains`` elastic chains of N = 20..200 beads (evenly spaced), each
collided (+V0 / -V0) at ``--collisions / --chains`` speeds V0 = 0.05..1 m/s, for
``--duration`` s at the default step of each chain's fastest launch, recording every
1 us what a sweep reads (the felt force of two sensor beads, at N/3 and 2N/3, and the
energies). It is run three ways, interleaved, best of ``--repeat`` (>= 7) wall times:

* ``chain.simulate_many`` on all cores: every collision one task of one thread pool,
  longest first (the batched lean kernel, no Python between collisions);
* the same on one thread;
* the C yardstick (``benchmarks/c/rk4_chain.c``, ``cc -O3 -march=native``) on one
  core, collision after collision, at the same steps (it records every contact force:
  a little more than the sweep asks for).

It prints collisions per second per core against C's (target >= 0.75), the speed-up
of all cores over one (target >= 1.8 on 2 cores), and the fixed cost of a job (a fresh
Python process that imports the library and runs one small collision, numba's cache
warm): the number of collisions of the mean size a job must hold for its fixed cost to
be a tenth of its work. Load averages before and after; a figure taken with a load
average above the number of cores is "UNDER LOAD — not a measurement of the target".
The figures go to benchmarks/results/ (``measure.write_result``). Not a test: it reports.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time

import numba
import numpy as np
from measure import (
    C_FLAGS,
    MIN_REPEAT,
    Conditions,
    Figure,
    OtherProcesses,
    best_times,
    c_run,
    load_c,
    machine,
    write_result,
)

from chain.physics.builders import uniform_chain
from chain.physics.materials import STEEL_100C6, contact_stiffness, sphere_mass
from chain.physics.model import launch_velocities
from chain.physics.simulation import DEFAULT_RECORD_INTERVAL, felt_contacts, simulate_many

RADIUS = 13e-3  # m, the paper's beads
SPEEDS = (0.05, 1.0)  # m/s, range of V0
JOB_START = (
    "import time; t = time.perf_counter(); "
    "from chain.physics.builders import uniform_chain; "
    "from chain.physics.simulation import simulate; "
    "simulate(uniform_chain(20), 0.3, 0.3, duration=1e-5, contacts=(), beads=()); "
    "print(time.perf_counter() - t)"
)


def sweep_runs(args) -> list[dict]:
    """The sweep as simulate_many runs: one run (a batch of speeds) per chain."""
    sizes = np.unique(np.linspace(20, 200, args.chains).round().astype(int))
    per_chain = math.ceil(args.collisions / len(sizes))
    speeds = np.geomspace(*SPEEDS, per_chain)
    runs = []
    for n_beads in sizes:
        model = uniform_chain(int(n_beads))
        sensors = (n_beads // 3, 2 * n_beads // 3)
        runs.append(
            {
                "model": model,
                "v_left": speeds,
                "v_right": speeds,
                "contacts": felt_contacts(model, sensors),
                "beads": (),
            }
        )
    return runs


def c_sweep(function, results) -> None:
    """The sweep in C, one collision after another, at the steps the library used."""
    mass = sphere_mass(STEEL_100C6, RADIUS)
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    for result in results:
        every = round(DEFAULT_RECORD_INTERVAL / result.dt)
        n_steps = (len(result.time) - 1) * every
        velocity = launch_velocities(result.model, result.v_left, result.v_right)
        for launch in velocity:
            c_run(function, launch, mass, kappa, 0.0, result.dt, n_steps, every)


def job_fixed_cost(repeat: int) -> float:
    """Best wall time of a fresh process that imports the library and runs one small
    collision (numba's cache warm), s."""
    best = math.inf
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", JOB_START], check=True, capture_output=True)
        best = min(best, time.perf_counter() - start)
    return best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--collisions", type=int, default=1000)
    parser.add_argument("--chains", type=int, default=50, help="chain sizes in 20..200")
    parser.add_argument("--duration", type=float, default=1e-3, help="s per collision")
    parser.add_argument("--repeat", type=int, default=MIN_REPEAT)
    args = parser.parse_args()
    cores = numba.get_num_threads()
    conditions = Conditions()
    print(f"machine: {machine()}, numba threads {cores}; C flags: {' '.join(C_FLAGS)}")
    conditions.sample("before")
    runs = sweep_runs(args)
    collisions = sum(len(run["v_left"]) for run in runs)
    common = {"duration": args.duration}
    results = simulate_many(runs, **common)  # compile / load the kernels
    with tempfile.TemporaryDirectory() as folder, OtherProcesses(interval=1.0) as others:
        c_function, how = load_c(folder)
        print(f"C yardstick: {how}" if c_function else f"C yardstick skipped: {how}")
        contenders = {
            f"sweep, {cores} threads": lambda: simulate_many(runs, threads=cores, **common),
            "sweep, 1 thread": lambda: simulate_many(runs, threads=1, **common),
        }
        if c_function is not None:
            contenders["C, 1 core"] = lambda: c_sweep(c_function, results)
        best = best_times(contenders, args.repeat, clock=time.perf_counter)
        fixed = job_fixed_cost(args.repeat)
    conditions.sample("after")
    figures = []
    sizes = [run["model"].n_beads for run in runs]
    print(
        f"\n{collisions} collisions of N = {min(sizes)}..{max(sizes)} ({len(runs)} chains), "
        f"{args.duration * 1e3:g} ms each, V0 = {SPEEDS[0]}..{SPEEDS[1]} m/s"
    )
    for name, seconds in best.items():
        print(f"  {name:16s} {seconds:8.2f} s = {collisions / seconds:8.1f} collisions/s")
    all_cores, one = best[f"sweep, {cores} threads"], best["sweep, 1 thread"]
    speed_up = one / all_cores
    per_core = collisions / all_cores / cores
    print(f"\n== summary (best of {args.repeat} interleaved, wall time)")
    verdict = conditions.verdict(speed_up >= 1.8) if cores == 2 else "not 2 cores"
    print(f"speed-up {cores} threads / 1: {speed_up:.2f}  (target >= 1.8 on 2 cores: {verdict})")
    figures.append(
        Figure(f"speed-up, {cores} threads / 1", speed_up, "x",
               "the cores' share of the sweep's work (longest collision first)",
               ratio_to="the same sweep on 1 thread, same run", target=">= 1.8 on 2 cores",
               verdict=verdict)
    )  # fmt: skip
    if c_function is not None:
        c_rate = collisions / best["C, 1 core"]
        ratio = per_core / c_rate
        print(
            f"collisions/s per core, sweep on {cores} threads / C: {ratio:.2f}  (target >= "
            f"0.75: {conditions.verdict(ratio >= 0.75)}); on 1 thread / C: "
            f"{collisions / one / c_rate:.2f}"
        )
        c_yardstick = f"C RK4 ({' '.join(C_FLAGS)}) on 1 core, same run"
        steps = "the kernel's steps, as C's (the same RK4 at the same step)"
        figures += [
            Figure(f"collisions/s per core, {cores} threads / C", ratio, "x", steps,
                   ratio_to=c_yardstick, target=">= 0.75",
                   verdict=conditions.verdict(ratio >= 0.75)),
            Figure("collisions/s, 1 thread / C", collisions / one / c_rate, "x", steps,
                   ratio_to=c_yardstick),
        ]  # fmt: skip
    mean_work = one / collisions
    print(
        f"a job's fixed cost (fresh process, imports, cache load, one small collision): "
        f"{fixed:.2f} s = {fixed / mean_work:.0f} collisions of the mean size on one core; "
        f"a job of >= {math.ceil(10 * fixed / mean_work)} such collisions per core keeps it "
        "under a tenth of the work"
    )
    print(f"NUMBA_NUM_THREADS={os.environ.get('NUMBA_NUM_THREADS', 'unset')}")
    figures.append(
        Figure("a job's fixed cost", fixed, "s",
               "a fresh interpreter's imports and numba's cache load, one small collision")
    )  # fmt: skip
    write_result("bench_sweep", figures, conditions, others.share)


if __name__ == "__main__":
    main()
