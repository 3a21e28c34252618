"""How the simulation scales with the chain: time and peak memory for N = 1,000 to 100,000.

Run from the repository root::

    python benchmarks/bench_scale.py                  # N = 1,000, 10,000, 100,000
    python benchmarks/bench_scale.py --sizes 1000 10000

Each N runs in its own Python process (so that its peak memory, ``ru_maxrss``, is its
own): one collision (+V0 / -V0, V0 = 0.3 m/s) of N elastic beads for 5 ms at the
default step, recording every 1 us only what a lab records: the force felt by two
sensor beads (at N/3 and 2N/3: the two contacts around each) and the energies. It
prints the wall and CPU time of ``simulate`` (after compilation, one launch: one core),
of ``default_time_step`` alone, the process's peak resident memory, and the growth of
the time from one N to the next (10x more beads: linear growth is a ratio of 10).

Targets (issue 14): N = 10,000 in < 10 s and < 1 GB. Not a test: it reports.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

DURATION = 5e-3  # s
SPEED = 0.3  # m/s
RECORD_INTERVAL = 1e-6  # s


def one(n_beads: int) -> dict:
    """Run the benchmark for ``n_beads`` in this process; returns the figures."""
    from chain.physics.model import uniform_chain
    from chain.physics.simulation import default_time_step, simulate

    sensors = (n_beads // 3, 2 * n_beads // 3)
    contacts = [k for bead in sensors for k in (bead - 1, bead)]
    simulate(uniform_chain(10), SPEED, SPEED, duration=1e-5, contacts=[1], beads=())  # compile
    model = uniform_chain(n_beads)
    start = time.perf_counter()
    default_time_step(model, SPEED)
    step_time = time.perf_counter() - start
    start, cpu = time.perf_counter(), time.process_time()
    result = simulate(
        model,
        SPEED,
        SPEED,
        duration=DURATION,
        record_interval=RECORD_INTERVAL,
        contacts=contacts,
        beads=(),
    )
    elapsed = time.perf_counter() - start
    cpu = time.process_time() - cpu
    felt = [float(result.force_felt(bead).max()) for bead in sensors]
    return {
        "n_beads": n_beads,
        "seconds": elapsed,
        "cpu_seconds": cpu,
        "default_time_step_s": step_time,
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "steps": round(DURATION / result.dt),
        "samples": len(result.time),
        "energy_drift": float(result.energy_drift[0]),
        "peak_felt_force_N": felt,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1_000, 10_000, 100_000])
    parser.add_argument("--one", type=int, help=argparse.SUPPRESS)  # child process
    args = parser.parse_args()
    if args.one:
        print(json.dumps(one(args.one)))
        return
    print(
        f"one collision, V0 = {SPEED} m/s, {DURATION * 1e3} ms, records every 1 us: "
        "felt force at 2 sensor beads + energies; one process per N"
    )
    print(
        f"{'N':>8} {'time s':>8} {'CPU s':>8} {'growth':>7} {'dt_default s':>12} "
        f"{'peak MB':>8} {'steps':>7} {'drift':>8}"
    )
    previous = None
    for n_beads in args.sizes:
        done = subprocess.run(
            [sys.executable, __file__, "--one", str(n_beads)],
            capture_output=True,
            text=True,
            check=True,
        )
        figures = json.loads(done.stdout.strip().splitlines()[-1])
        # Growth in CPU time: on a shared machine the wall time also measures the others.
        growth = "" if previous is None else f"{figures['cpu_seconds'] / previous:.1f}"
        previous = figures["cpu_seconds"]
        print(
            f"{n_beads:>8} {figures['seconds']:8.2f} {figures['cpu_seconds']:8.2f} {growth:>7} "
            f"{figures['default_time_step_s']:12.4f} {figures['peak_mb']:8.0f} "
            f"{figures['steps']:>7} {figures['energy_drift']:8.1e}"
        )
    print("targets: N = 10,000 in < 10 s and < 1000 MB; growth ~10 per 10x N (linear)")


if __name__ == "__main__":
    main()
