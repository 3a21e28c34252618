"""What each of the two scheduler patches of chain.pipeline.run.snakemake_patches buys
(applied from workflow/rules/common.smk on Snakemake 9.27.1; docs/upstream/README.md).

**Wake-ups** (``coalesce_wakeups``): Snakemake runs through :data:`WRAPPER`, a few lines
of Python that start ``snakemake.cli.main()`` in-process, either as the workflow runs
(both patches) or with ``coalesce_wakeups`` replaced by a no-op first (the SIGTERM patch
still applied); the workflow has no switch for it. Each round, in a fresh copy of the
tree (workflow_runs: LAMMPS hidden, the copy's own store), both ways, in alternating
order, after a first paper run that filled numba's cache:

    paper   the paper run, warm: results/ and .snakemake/ removed before each
    sweep   an overlay of --chains chains (N = 10, 11, ...) x 3 models, 3 launch speeds,
            no experiment and no study, run with --until simulate: 300 simulate jobs of
            a fraction of a second of work each (their start-up dominates), so that
            the scheduler's share shows

Each run's wall time, Snakemake's own CPU (``getrusage(RUSAGE_SELF)`` of its process
at exit: every thread of it, none of its jobs) and the scheduler's passes (calls of
``JobScheduler._finish_jobs``, once per pass of its loop). Best of the rounds each way;
the ratio with / without is judged against 0.95 (the patch buys at least 5 %; one that
buys less is to be removed). Verdicts are never "met" when other processes took more
than 5 % of the CPU (measure.OtherProcesses).

**SIGTERM** (``stop_gracefully_off_the_main_thread``): the reproducer of
docs/upstream/sigterm-hang/ (plain Snakemake, 400 jobs of ``sleep 0.5`` on 4 cores) in
a copy, through the wrapper with that patch applied or not: SIGTERM at a random moment
in the 3 s after the first job wrote (the same moment both ways), and a run still alive
--hang-after s later is hung (then killed). Tries alternate between the two.

    python benchmarks/bench_scheduler.py                          # 3 rounds, 10 tries
    python benchmarks/bench_scheduler.py --rounds 1 --chains 10 --tries 2   # a check

Results: benchmarks/results/bench_scheduler.json (``measure.write_result``).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from measure import UNDER_LOAD, Conditions, Figure, OtherProcesses, write_result
from workflow_runs import Timed, copy_tree, environment, fresh, planned, run, started

#: Snakemake through a wrapper: ``python -c WRAPPER MODE REPORT snakemake-arguments...``.
#: MODE: "as-is" (the workflow's patches as it applies them), "no-wakeup-patch"
#: (coalesce_wakeups a no-op), "sigterm-patch" (stop_gracefully_off_the_main_thread
#: applied here, for a Snakefile that applies nothing). REPORT: a JSON file written at
#: the process's exit, after Snakemake's threads ended: its CPU s, the scheduler's
#: passes, and whether each patch was in place.
WRAPPER = """
import atexit, json, resource, sys
mode, report = sys.argv[1], sys.argv[2]
del sys.argv[1:3]
from snakemake.scheduling.job_scheduler import JobScheduler
from chain.pipeline.run import snakemake_patches as patches
if mode == "no-wakeup-patch":
    patches.coalesce_wakeups = lambda scheduler_class: False
elif mode == "sigterm-patch":
    patches.stop_gracefully_off_the_main_thread(JobScheduler)
snakemakes_wakeup, passes = JobScheduler._schedule_reevalutation, [0]
finish_jobs = JobScheduler._finish_jobs
def counted(self):
    passes[0] += 1
    return finish_jobs(self)
JobScheduler._finish_jobs = counted
def write_report():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    with open(report, "w") as handle:
        json.dump({"cpu_s": usage.ru_utime + usage.ru_stime, "passes": passes[0],
                   "wakeup_patch": JobScheduler._schedule_reevalutation
                   is not snakemakes_wakeup, "sigterm_patch": getattr(
                   JobScheduler.exit_gracefully, "_off_the_main_thread", False)}, handle)
atexit.register(write_report)
from snakemake.cli import main
main()
"""
#: The two ways of each workload: (name, wrapper mode).
WAYS = (("with", "as-is"), ("without", "no-wakeup-patch"))
#: The most a patch may leave of its run without it (with / without) to be kept.
KEEP_BELOW = 0.95
#: The sweep's models: the paper's two and half its relaxation time.
SWEEP_MODELS = (("elastic", 0.0), ("viscoelastic-half", 0.29e-6), ("viscoelastic", 0.58e-6))
#: The reproducer of the SIGTERM hang, in the tree.
SIGTERM_REPRODUCER = Path("docs/upstream/sigterm-hang/Snakefile")
BOUNDS = {
    "paper": "the jobs' work on 2 cores; the scheduler's passes in Snakemake's process",
    "sweep": "the jobs' start-up on 2 cores; the scheduler's passes over many ready jobs",
    "sigterm": "whether the SIGTERM handler waits for the lock the main thread holds",
}


def sweep_overlay(chains: int) -> str:
    """The sweep: ``chains`` chains (N = 10, 11, ...; sensors symmetric about the middle
    as in whatif/sweep.yaml) x :data:`SWEEP_MODELS`, 3 launch speeds, simulated for as
    long as the config check asks (1.2 x the slowest wave's passage of the farthest
    sensor: ~50 us a bead at 0.5 m/s, and the pulse). No experiment, study or long chain."""
    lines, farthest = ["run_name: bench_sweep", "chains:"], 0
    for n in range(10, 10 + chains):
        first = n // 2 - 3
        lines.append(f"  - {{N: {n}, sensors: [{first}, {n + 1 - first}]}}")
        farthest = max(farthest, n + 1 - first)
    lines.append("models:")
    lines += [f"  - {{name: {name}, eta_s: {eta}}}" for name, eta in SWEEP_MODELS]
    lines += [
        "long_chains: {N: []}",
        "launch: {v0_min_m_s: 0.5, v0_max_m_s: 1.0, count: 3}",
        f"simulation: {{duration_s: {6.2e-5 * farthest + 2e-4:.3g}}}",
        # The ablation's variants are checked against the virtual experiment's record
        # even when the experiment is off (5.4 ms for N = 109): long enough for them.
        f"experiment: {{source: none, virtual: {{duration_s: {1e-4 * farthest + 5e-4:.3g}}}}}",
        "studies: {ablation: false, c_sensitivity: false, mechanisms: false}",
    ]
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class Measured:
    """One run through the wrapper: its time, Snakemake's CPU s, the scheduler's passes,
    the jobs it started."""

    timed: Timed
    cpu_s: float
    passes: int
    jobs: int


def wrapped(mode: str, report: Path, *args: str) -> list[str]:
    """The command of a Snakemake run through :data:`WRAPPER`."""
    return [sys.executable, "-c", WRAPPER, mode, str(report), *args]


def measure_run(work: Path, env: dict, mode: str, args: list[str]) -> Measured:
    """A run of ``args`` in ``work`` from nothing computed (numba's cache kept)."""
    fresh(work)
    report = work / "wrapper_report.json"
    report.unlink(missing_ok=True)
    timed, printed = run(wrapped(mode, report, *args), work, env)
    read = json.loads(report.read_text())
    expected = mode != "no-wakeup-patch"
    if read["wakeup_patch"] != expected:
        raise SystemExit(f"{mode}: the wake-up patch is {'not ' * expected}in place")
    jobs = sum(started(printed).values())
    return Measured(timed, read["cpu_s"], read["passes"], jobs)


def wakeup_rounds(work: Path, args, conditions: Conditions) -> dict:
    """Workload -> way -> [Measured] of each round."""
    env, cores = environment(work), ["--cores", str(args.cores)]
    (work / "bench_sweep.yaml").write_text(sweep_overlay(args.chains))
    (work / "bench_warmup.yaml").write_text(sweep_overlay(1))
    workloads = {}
    if "paper" in args.parts:
        workloads["paper"] = cores
    if "sweep" in args.parts:
        sweep = [*cores, "--configfile", "bench_sweep.yaml", "--until", "simulate"]
        workloads["sweep"] = sweep
        _, dry = run([sys.executable, "-m", "snakemake", *sweep, "-n"], work, env)
        print(f"sweep: {dict(planned(dry))} jobs planned by its dry run", flush=True)
    # numba's cache filled first: by a paper run, or by a sweep of one chain (3 jobs).
    first = ["--configfile", "bench_warmup.yaml", "--until", "simulate"]
    first = [sys.executable, "-m", "snakemake", *cores, *([] if "paper" in workloads else first)]
    timed, _ = run(first, work, env)
    print(f"first run (numba's cache filled): {timed.wall:.1f} s", flush=True)
    measured = {w: {way: [] for way, _ in WAYS} for w in workloads}
    for k in range(args.rounds):
        conditions.sample(f"before round {k + 1}")
        for workload, arguments in workloads.items():
            for way, mode in WAYS[:: 1 if k % 2 == 0 else -1]:
                one = measure_run(work, env, mode, arguments)
                measured[workload][way].append(one)
                print(f"  round {k + 1}, {workload} {way} the wake-up patch: "
                      f"{one.timed.wall:.1f} s, Snakemake's CPU {one.cpu_s:.1f} s, "
                      f"{one.passes} passes, {one.jobs} jobs, other processes "
                      f"{one.timed.others:.1%} of the CPU", flush=True)  # fmt: skip
        conditions.sample(f"after round {k + 1}")
    return measured


def verdict(met: bool, *timed: Timed) -> str:
    loaded = [t for t in timed if not t.quiet]
    if loaded:
        return f"{UNDER_LOAD} (others {max(t.others for t in loaded):.0%})"
    return "met" if met else "not met"


def wakeup_figures(measured: dict) -> list[Figure]:
    """Per workload, the best of each way: the wall time with the patch, and the wall
    time and Snakemake's CPU with it as ratios to without (each way's best run by that
    measure; the CPU's absolute values and the passes in the figure's name)."""
    figures = []
    for workload, ways in measured.items():
        label = "warm paper run" if workload == "paper" else "sweep"
        label += f" ({max(m.jobs for m in ways['with'])} jobs)"
        wall = {way: min(runs, key=lambda m: m.timed.wall) for way, runs in ways.items()}
        cpu = {way: min(runs, key=lambda m: m.cpu_s) for way, runs in ways.items()}
        figures.append(Figure(f"{label}: wall with the wake-up patch", wall["with"].timed.wall,
                              "s", BOUNDS[workload]))  # fmt: skip
        for what, best, value in (
            ("wall", wall, lambda m: m.timed.wall),
            ("Snakemake's CPU", cpu, lambda m: m.cpu_s),
        ):
            ratio = value(best["with"]) / value(best["without"])
            judged = verdict(ratio <= KEEP_BELOW, best["with"].timed, best["without"].timed)
            detail = (f"{value(best['with']):.1f} s / {value(best['without']):.1f} s; "
                      f"{best['with'].passes} / {best['without'].passes} passes")  # fmt: skip
            print(f"  {label}, {what} with / without the wake-up patch: {ratio:.3f} "
                  f"({detail}; keep it if <= {KEEP_BELOW}: {judged})")  # fmt: skip
            name = f"{label}: {what} with / without the wake-up patch"
            figures.append(Figure(name if what == "wall" else f"{name} ({detail})", ratio,
                                  "x", BOUNDS[workload], "the same run without the patch, "
                                  "same rounds", f"<= {KEEP_BELOW}", judged))  # fmt: skip
    return figures


def sigterm_try(folder: Path, env: dict, mode: str, delay: float, hang_after: float) -> bool:
    """One try of the reproducer in ``folder``: whether the run hung."""
    for name in ("out", ".snakemake"):
        shutil.rmtree(folder / name, ignore_errors=True)
    (folder / "wrapper_report.json").unlink(missing_ok=True)
    command = wrapped(mode, folder / "wrapper_report.json", "--cores", "4", "--quiet")
    with (folder / f"{mode}.log").open("w") as log:
        process = subprocess.Popen(command, cwd=folder, env=env, stdout=log, stderr=log,
                                   stdin=subprocess.DEVNULL, start_new_session=True)  # fmt: skip
    try:
        deadline = time.monotonic() + 300
        while not any((folder / "out").glob("*")):  # jobs are running
            if process.poll() is not None or time.monotonic() > deadline:
                raise SystemExit(f"the reproducer did not start its jobs: {folder / mode}.log")
            time.sleep(0.1)
        time.sleep(delay)
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=hang_after)
        except subprocess.TimeoutExpired:
            return True
        report = json.loads((folder / "wrapper_report.json").read_text())
        if report["sigterm_patch"] != (mode == "sigterm-patch"):
            raise SystemExit(f"{mode}: the SIGTERM patch is not as asked")
        return False
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)  # our own run's group: it and its jobs
            process.wait()


def sigterm_figures(work: Path, args, conditions: Conditions) -> tuple[list[Figure], list]:
    """Hangs of the reproducer with and without the SIGTERM patch over ``args.tries``."""
    folder = work / "sigterm"
    folder.mkdir()
    shutil.copy(work / SIGTERM_REPRODUCER, folder / "Snakefile")
    env, draw = environment(work), random.Random(args.seed)
    hung = {"sigterm-patch": 0, "as-is": 0}
    conditions.sample("before the SIGTERM tries")
    start = time.perf_counter()
    with OtherProcesses() as others:
        for k in range(args.tries):
            delay = draw.uniform(0, 3)
            for mode in list(hung)[:: 1 if k % 2 == 0 else -1]:
                hung[mode] += sigterm_try(folder, env, mode, delay, args.hang_after)
            print(f"  try {k + 1}: SIGTERM {delay:.2f} s after the jobs started; hung so far: "
                  f"{hung['sigterm-patch']} with the patch, {hung['as-is']} without",
                  flush=True)  # fmt: skip
    conditions.sample("after the SIGTERM tries")
    timed = Timed(time.perf_counter() - start, others.share)
    figures = []
    for mode, way in (("sigterm-patch", "with"), ("as-is", "without")):
        judged = verdict(hung[mode] == 0, timed) if way == "with" else ""
        print(f"  SIGTERM reproducer {way} the patch: hung in {hung[mode]} of {args.tries} "
              f"tries (still alive {args.hang_after:g} s after the signal)")  # fmt: skip
        figures.append(Figure(f"SIGTERM reproducer, runs hung {way} the patch",
                              hung[mode], f"of {args.tries}", BOUNDS["sigterm"], None,
                              "0" if way == "with" else "", judged))  # fmt: skip
    return figures, [timed]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3, help="interleaved rounds")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--chains", type=int, default=100, help="the sweep's chains (x 3)")
    parser.add_argument("--tries", type=int, default=10, help="SIGTERM tries each way")
    parser.add_argument("--hang-after", type=float, default=30.0,
                        help="s after the SIGTERM that a live run counts as hung")  # fmt: skip
    parser.add_argument("--seed", type=int, default=1, help="of the SIGTERM moments")
    parser.add_argument("--parts", nargs="+", default=["paper", "sweep", "sigterm"],
                        choices=["paper", "sweep", "sigterm"])  # fmt: skip
    parser.add_argument("--commit", help="measure this commit (default: the work tree)")
    parser.add_argument("--keep", type=Path, help="work under this folder and keep it")
    args = parser.parse_args(argv)
    base = args.keep or Path(tempfile.mkdtemp(prefix="bench_scheduler_"))
    work = base / "tree"
    shutil.rmtree(work, ignore_errors=True)
    conditions, figures, timings = Conditions(), [], []
    try:
        copy_tree(work, args.commit)
        if {"paper", "sweep"} & set(args.parts):
            measured = wakeup_rounds(work, args, conditions)
            print(f"\nbest of {args.rounds} interleaved round(s):")
            figures += wakeup_figures(measured)
            timings += [m.timed for ways in measured.values() for r in ways.values() for m in r]
        if "sigterm" in args.parts:
            more, timed = sigterm_figures(work, args, conditions)
            figures, timings = figures + more, timings + timed
        walls = [t.wall for t in timings]
        others = (sum(t.others * t.wall for t in timings) / sum(walls) if sum(walls) > 0
                  else max(t.others for t in timings))  # fmt: skip
        write_result("bench_scheduler", figures, conditions, others, own_load=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
