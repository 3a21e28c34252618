"""How the simulation scales with the chain: time and peak memory for N = 1,000 to 100,000.

Run from the repository root::

    python benchmarks/bench_scale.py                  # N = 1,000, 10,000, 100,000 x 1 ms
    python benchmarks/bench_scale.py --sizes 1000 10000 --duration 5e-3
    python benchmarks/bench_scale.py --sensors        # record 2 sensor beads only

Each N runs in its own Python process on one thread (so that its peak memory,
``VmHWM`` through ``measure.peak_memory_mb``, is its own): one collision (+V0 / -V0,
V0 = 0.3 m/s) of N elastic beads for ``--duration`` at the default step, through
``chain.simulate`` with its defaults (an overview of a long chain, every
stride-th contact and bead), or with ``--sensors`` recording only the force felt by two
sensor beads (at N/3 and 2N/3) and the energies. It prints the best CPU and wall time
of ``--repeat`` (>= 7) runs of ``simulate`` (after compilation), ``default_time_step``
alone, the process's peak resident memory, and the growth of the time from one N to
the next (10x more beads: linear growth is a ratio of 10), with the load average
before and after, and writes them to benchmarks/results/ (``measure.write_result``).

Targets: 100,000 beads x 1 ms at most linear in N (growth <= ~10); with sensors,
N = 10,000 x 5 ms in < 10 s and < 1 GB (the integrator's own < 4 s and < 300 MB:
bench_integrator.py).
Not a test: it reports.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time

from measure import (
    MIN_REPEAT,
    Conditions,
    Figure,
    OtherProcesses,
    check_repeat,
    peak_memory_mb,
    write_result,
)

SPEED = 0.3  # m/s
RECORD_INTERVAL = 1e-6  # s


def one(n_beads: int, duration: float, sensors_only: bool, repeat: int) -> dict:
    """Run the benchmark for ``n_beads`` in this process; returns the figures."""
    from chain.physics.builders import uniform_chain
    from chain.physics.simulation import default_time_step, simulate

    sensors = (n_beads // 3, 2 * n_beads // 3)
    record = {}
    if sensors_only:
        record = {"contacts": [k for bead in sensors for k in (bead - 1, bead)], "beads": ()}
    simulate(uniform_chain(10), SPEED, SPEED, duration=1e-5, contacts=[1], beads=())  # compile
    model = uniform_chain(n_beads)
    start = time.perf_counter()
    default_time_step(model, SPEED)
    step_time = time.perf_counter() - start
    best_wall = best_cpu = math.inf
    for _ in range(repeat):
        start, cpu = time.perf_counter(), time.process_time()
        result = simulate(
            model, SPEED, SPEED, duration=duration, record_interval=RECORD_INTERVAL, **record
        )
        best_wall = min(best_wall, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    felt = [float(result.force_felt(bead).max()) for bead in sensors] if record else []
    return {
        "n_beads": n_beads,
        "seconds": best_wall,
        "cpu_seconds": best_cpu,
        "default_time_step_s": step_time,
        "peak_mb": peak_memory_mb(),
        "steps": round(duration / result.dt),
        "samples": len(result.time),
        "recorded_contacts": result.contact_force.shape[2],
        "energy_drift": float(result.energy_drift[0]),
        "peak_felt_force_N": felt,
    }


def result_figures(figures: dict, previous: float | None, args) -> list:
    """One N's figures for the results file: CPU time, growth over the previous N,
    peak memory."""
    n_beads, cpu = figures["n_beads"], figures["cpu_seconds"]
    what = f"N = {n_beads:,} x {args.duration * 1e3:g} ms"
    moving = "the beads the waves have reached (chain.physics.at_rest skips the others)"
    rows = [Figure(f"{what}, CPU", cpu, "s", moving)]
    if previous is not None:
        rows.append(
            Figure(f"{what}, CPU growth", cpu / previous, "x", moving,
                   ratio_to="the previous N's CPU, same run", target="<= ~10 (linear in N)")
        )  # fmt: skip
    rows.append(
        Figure(f"{what}, peak memory", figures["peak_mb"], "MB",
               "the interpreter and numba, plus the record asked for")
    )  # fmt: skip
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    parser.add_argument("--duration", type=float, default=1e-3, help="simulated time, s")
    parser.add_argument("--sensors", action="store_true", help="record 2 sensor beads only")
    parser.add_argument("--repeat", type=int, default=MIN_REPEAT)
    parser.add_argument("--one", type=int, help=argparse.SUPPRESS)  # child process
    args = parser.parse_args()
    check_repeat(args.repeat)
    if args.one:
        print(json.dumps(one(args.one, args.duration, args.sensors, args.repeat)))
        return
    what = "felt force at 2 sensor beads" if args.sensors else "simulate's defaults"
    print(
        f"one collision, V0 = {SPEED} m/s, {args.duration * 1e3:g} ms, records every 1 us: "
        f"{what} + energies; one process per N, one thread, best of {args.repeat}"
    )
    conditions = Conditions()
    conditions.sample("before")
    print(
        f"{'N':>8} {'time s':>8} {'CPU s':>8} {'growth':>7} {'dt_default s':>12} "
        f"{'peak MB':>8} {'steps':>7} {'contacts':>8} {'drift':>8}"
    )
    previous = None
    environment = {**os.environ, "NUMBA_NUM_THREADS": "1"}
    measured = []
    with OtherProcesses(interval=1.0) as others:
        for n_beads in args.sizes:
            command = [sys.executable, __file__, "--one", str(n_beads)]
            command += ["--repeat", str(args.repeat), "--duration", str(args.duration)]
            command += ["--sensors"] if args.sensors else []
            done = subprocess.run(
                command, capture_output=True, text=True, check=True, env=environment
            )
            figures = json.loads(done.stdout.strip().splitlines()[-1])
            # Growth in CPU time: on a shared machine the wall time also measures the others.
            growth = "" if previous is None else f"{figures['cpu_seconds'] / previous:.1f}"
            measured += result_figures(figures, previous, args)
            previous = figures["cpu_seconds"]
            print(
                f"{n_beads:>8} {figures['seconds']:8.2f} {figures['cpu_seconds']:8.2f} "
                f"{growth:>7} {figures['default_time_step_s']:12.4f} "
                f"{figures['peak_mb']:8.0f} {figures['steps']:>7} "
                f"{figures['recorded_contacts']:>8} {figures['energy_drift']:8.1e}"
            )
    conditions.sample("after")
    print(
        "target: growth <= ~10 per 10x N (at most linear; below it while the waves reach "
        "fewer beads than the chain has: chain.physics.at_rest skips the others)"
        + ("; UNDER LOAD — times not a measurement of the target" if conditions.under_load else "")
    )
    name = "bench_scale_sensors" if args.sensors else "bench_scale"
    write_result(name, measured, conditions, others.share)


if __name__ == "__main__":
    main()
