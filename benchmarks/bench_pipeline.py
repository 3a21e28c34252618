"""What a user waits for: the paper run (numba's cache cold, and warm), three what-ifs
and the tests, each against a yardstick measured in the same rounds.

Every round works in a fresh copy of the checkout (the files git tracks, no numba cache,
no results, no result store: a fresh clone), whose ``src`` the jobs import, and runs in
order::

    cold        snakemake --cores 2               numba's cache empty
    warm        the same, results/ and .snakemake/ removed (the store with them),
                numba's cache kept
    brass       snakemake --cores 2 --configfile whatif/brass.yaml     after the paper run
    analysis    an overlay: run_name bench_analysis, analysis: {main_estimator: peak}
    figure      an overlay: run_name bench_figure, figures: {representative_force_N: 100}

The **yardstick** is the paper run of :data:`BASELINE_COMMIT` in a fresh copy of that
commit, on the same interpreter, cold and then warm as above, in every round. The
targets are ratios: the cold run to the yardstick's cold run, every other scenario to
its warm run (:data:`TARGETS`). Rounds are interleaved (each round runs every command
once, so that load hits all of them alike) and the best of each is kept, with the load
average before and after each round, and a verdict that is never "met" when other
processes took more than 5 % of the machine's CPU during the command or its yardstick
(measure.OtherProcesses). Then the README's test command runs once in the last copy
(``--no-tests`` skips it)::

    python benchmarks/bench_pipeline.py                  # 3 rounds and the tests
    python benchmarks/bench_pipeline.py --repeat 1 --no-tests --keep /tmp/bench

Each scenario's jobs are those Snakemake started (its ``rule`` lines): a job that takes
a stored result starts nothing, and the run's first line says how many did. A what-if
that changes no simulation's input must start no simulation job, and its dry run must
list the same jobs. Per rule, the paper run's jobs and their summed wall time from
Snakemake's start and finish lines (whole seconds). The best times, their ratios and
verdicts go to benchmarks/results/ (``measure.write_result``).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).parent))
from measure import (
    MAX_OTHER_SHARE,
    UNDER_LOAD,
    Conditions,
    Figure,
    OtherProcesses,
    write_result,
)

ROOT = Path(__file__).resolve().parents[1]

#: (name, snakemake arguments, overlay written into the copy or None), in order.
SCENARIOS = (
    ("cold", [], None),
    ("warm", [], None),
    ("brass", ["--configfile", "whatif/brass.yaml"], None),
    ("analysis", ["--configfile", "bench_analysis.yaml"],
     "run_name: bench_analysis\nanalysis: {main_estimator: peak}\n"),
    ("figure", ["--configfile", "bench_figure.yaml"],
     "run_name: bench_figure\nfigures: {representative_force_N: 100}\n"),
)  # fmt: skip
#: The yardstick's commit: each job its own process, no reuse across runs.
BASELINE_COMMIT = "9fb9b1b"
#: Scenario -> (the yardstick's run it is a ratio to, the largest ratio).
TARGETS = {
    "cold": ("cold", 0.60),
    "warm": ("warm", 0.55),
    "brass": ("warm", 0.35),
    "analysis": ("warm", 0.12),
    "figure": ("warm", 0.10),
}
#: Rules that integrate a chain (or run LAMMPS): an analysis what-if should run none.
SIMULATIONS = (
    "simulate", "virtual_experiment", "ssw_track", "ssw_fields", "lammps_setting",
    "lammps_check", "ablation_variant", "c_sensitivity",
)  # fmt: skip
#: What bounds each scenario's time (benchmarks/README.md has the measurements).
BOUNDS = {
    "yardstick": "the baseline commit's jobs, each in its own process",
    "cold": "CPU: numba's cold compile on the critical path, then the jobs' CPU on 2 cores",
    "warm": "CPU: every job's work and start-up on 2 cores, nothing compiled",
    "brass": "CPU: the new material's simulations and everything downstream",
    "analysis": "CPU: the fits and figures downstream of the estimator, no simulation",
    "figure": "CPU: the space-time figure's cells drawn to PDF and PNG, and the article",
    "tests": "CPU: the suite's Snakemake runs and the kernel tests' cold compiles",
}

_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
_START = re.compile(r"^\s*(?:local)?rule (\w+):$")
_FIELD = re.compile(r"^\s+jobid: (\d+)$")
_FINISH = re.compile(r"^Finished jobid: (\d+) \(Rule: (\w+)\)$")


def jobs_of(printed: str) -> pd.DataFrame:
    """One row per job Snakemake started: rule and wall s (its start and finish lines,
    whole seconds)."""
    jobs, stamp, current = {}, None, None
    for line in printed.splitlines():
        if match := _STAMP.match(line):
            stamp = datetime.strptime(match.group(1), "%a %b %d %H:%M:%S %Y")
        elif match := _START.match(line):
            current = {"rule": match.group(1), "start": stamp}
        elif current is not None and (match := _FIELD.match(line)):
            jobs[int(match.group(1))] = current
        elif match := _FINISH.match(line):
            job = jobs.get(int(match.group(1)))
            if job is not None and job["start"] is not None:
                job["wall_s"] = (stamp - job["start"]).total_seconds()
    rows = [{"rule": j["rule"], "wall_s": j.get("wall_s", 0.0)} for j in jobs.values()]
    frame = pd.DataFrame(rows, columns=["rule", "wall_s"])
    return frame[frame["rule"] != "all"]


def taken(printed: str) -> int:
    """How many jobs took a stored result (the run's first line says)."""
    found = re.search(r"(\d+) of \d+ jobs take a stored result", printed)
    return int(found.group(1)) if found else 0


def copy_checkout(work: Path) -> None:
    """The files git tracks (as they are in the work tree) into ``work``."""
    tracked = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split("\0")
    for name in filter(None, tracked):
        path = ROOT / name
        if path.is_file():
            target = work / name
            target.parent.mkdir(parents=True, exist_ok=True)
            # A tracked link stays a link, as in a clone (tests/test_measured.py checks
            # that the metadata schema of the workflow is the package's file).
            shutil.copy2(path, target, follow_symlinks=False)


def copy_commit(commit: str, work: Path) -> None:
    """The files of ``commit`` (as git archive gives them) into ``work``."""
    work.mkdir(parents=True)
    archive = subprocess.run(
        ["git", "archive", "--format=tar", commit], cwd=ROOT, capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(work)], input=archive, check=True)


def environment(work: Path) -> dict:
    """The environment of a run in the copy: its jobs import the copy's library."""
    path = os.pathsep.join([str(work / "src"), os.environ.get("PYTHONPATH", "")])
    return {**os.environ, "PYTHONPATH": path}


@dataclass(frozen=True)
class Timed:
    """A command's wall time, s, and the share of the machine's CPU that other
    processes used meanwhile (measure.OtherProcesses)."""

    wall: float
    others: float

    @property
    def quiet(self) -> bool:
        return self.others <= MAX_OTHER_SHARE


def run(command: list[str], work: Path) -> tuple[Timed, str]:
    """Run ``command`` in the copy; its time and what it printed."""
    start = time.perf_counter()
    with OtherProcesses() as others:
        done = subprocess.run(
            command, cwd=work, capture_output=True, text=True, env=environment(work),
            stdin=subprocess.DEVNULL,
        )  # fmt: skip
    elapsed = Timed(time.perf_counter() - start, others.share)
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-4000:] + done.stderr[-4000:])
        raise SystemExit(f"failed in {work}: {' '.join(command)}")
    return elapsed, done.stdout + done.stderr


def fresh(work: Path) -> None:
    """Remove a copy's results and Snakemake's records (the store with them), keep
    numba's cache: the next paper run is a warm one."""
    shutil.rmtree(work / "results", ignore_errors=True)
    shutil.rmtree(work / ".snakemake", ignore_errors=True)


def yardstick(work: Path, cores: int) -> dict:
    """The paper run of :data:`BASELINE_COMMIT` in a fresh copy of it, cold then warm."""
    copy_commit(BASELINE_COMMIT, work)
    command = [sys.executable, "-m", "snakemake", "--cores", str(cores)]
    timings = {}
    for name in ("cold", "warm"):
        if name == "warm":
            fresh(work)
        timings[name], _ = run(command, work)
        print(f"  yardstick {name} ({BASELINE_COMMIT} paper run): {timings[name].wall:.1f} s, "
              f"other processes {timings[name].others:.1%} of the CPU", flush=True)  # fmt: skip
    return timings


def one_round(work: Path, cores: int) -> dict:
    """Every scenario once, in order, in a fresh copy: name -> (time, jobs started, jobs
    taken from the store, rules a dry run lists)."""
    copy_checkout(work)
    timings = {}
    for name, args, overlay in SCENARIOS:
        if overlay:
            (work / f"bench_{name}.yaml").write_text(overlay)
        if name == "warm":
            fresh(work)
        command = [sys.executable, "-m", "snakemake", "--cores", str(cores), *args]
        _, dry = run([*command, "-n"], work) if overlay else (None, "")
        timed, printed = run(command, work)
        jobs, listed = jobs_of(printed), set(re.findall(r"^(?:local)?rule (\w+):$", dry, re.M))
        timings[name] = (timed, jobs, taken(printed), listed - {"all"})
        print(f"  {name}: {timed.wall:.1f} s, {len(jobs)} jobs started, {taken(printed)} "
              f"taken from the store, other processes {timed.others:.1%} of the CPU",
              flush=True)  # fmt: skip
    return timings


#: Why a what-if starts the simulation jobs it starts.
BOUND_SIMULATIONS = {
    "analysis": "no simulation's input changes",
    "figure": "ssw_fields integrates the collision at the new representative force, "
    "recording every bead (the paper run's jobs record the sensors only)",
}


def per_rule(jobs: pd.DataFrame) -> pd.DataFrame:
    """Per rule of a run's jobs: how many and their summed wall time, s."""
    return (
        jobs.groupby("rule")
        .agg(jobs=("rule", "size"), wall_s=("wall_s", "sum"))
        .sort_values("wall_s", ascending=False)
    )


def verdict(ratio: float, limit: float, timed: Timed, scale: Timed) -> str:
    """Met or not against ``limit``; never "met" when other processes took more than
    MAX_OTHER_SHARE of the CPU during the command or during its yardstick."""
    loaded = [t for t in (timed, scale) if not t.quiet]
    if loaded:
        return f"{UNDER_LOAD} (others {max(t.others for t in loaded):.0%})"
    return "met" if ratio <= limit else "not met"


def summarise(rounds: list[dict], yardsticks: list[dict]) -> list[Figure]:
    """The best round of each scenario, and its ratio to the best yardstick run it is
    judged against; returns them as the figures of the results file."""
    figures = []
    print(f"\nbest of {len(rounds)} interleaved round(s), --cores as given:")
    best = {k: min((y[k] for y in yardsticks), key=lambda t: t.wall) for k in ("cold", "warm")}
    for kind, timed in best.items():
        print(f"  yardstick {kind}: {timed.wall:6.1f} s ({BASELINE_COMMIT}'s paper run)")
        figures.append(Figure(f"yardstick, {kind}", timed.wall, "s", BOUNDS["yardstick"]))
    for name, _, _ in SCENARIOS:
        timed, jobs, reused, _ = min((r[name] for r in rounds), key=lambda r: r[0].wall)
        against, limit = TARGETS[name]
        ratio = timed.wall / best[against].wall
        judged = verdict(ratio, limit, timed, best[against])
        rules = sorted(set(jobs["rule"]))
        shown = ", ".join(rules) if len(rules) <= 6 else f"{len(rules)} rules"
        print(f"  {name:9s} {timed.wall:6.1f} s  {ratio:6.3f} x the yardstick's {against} run "
              f"(target <= {limit}: {judged}); {len(jobs)} jobs started ({shown}), "
              f"{reused} taken")  # fmt: skip
        figures.append(Figure(f"{name} ({len(jobs)} jobs started, {reused} taken)", timed.wall,
                              "s", BOUNDS[name]))  # fmt: skip
        figures.append(Figure(f"{name} / yardstick {against}", ratio, "x", BOUNDS[name],
                              f"the yardstick: {BASELINE_COMMIT}'s {against} paper run, best "
                              "round", f"<= {limit}", judged))  # fmt: skip
    for name in ("analysis", "figure"):
        started = {rule for r in rounds for rule in r[name][1]["rule"]}
        listed = {rule for r in rounds for rule in r[name][3]}
        simulated = sorted((started | listed) & set(SIMULATIONS))
        same = all(set(r[name][1]["rule"]) == r[name][3] for r in rounds)
        print(
            f"  {name} what-if: simulation jobs started or listed by its dry run: "
            f"{', '.join(simulated) or 'none'}; dry run lists what it starts: {same}"
        )
        figures.append(Figure(f"{name} what-if, simulation jobs started or listed",
                              len(simulated), "jobs", BOUND_SIMULATIONS[name], None,
                              "0", "met" if not simulated and same else "not met"))  # fmt: skip
    return figures


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3, help="interleaved rounds")
    parser.add_argument("--no-tests", action="store_true", help="skip the test suite")
    parser.add_argument("--keep", type=Path, help="work under this folder and keep it")
    args = parser.parse_args(argv)
    base = args.keep or Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    conditions = Conditions()
    rounds, yardsticks = [], []
    try:
        for k in range(args.repeat):
            for folder in (f"round{k}", f"yardstick{k}"):
                shutil.rmtree(base / folder, ignore_errors=True)
            conditions.sample(f"before round {k + 1}")
            yardsticks.append(yardstick(base / f"yardstick{k}", args.cores))
            rounds.append(one_round(base / f"round{k}", args.cores))
            conditions.sample(f"after round {k + 1}")
        print("\nthe warm paper run of the last round, per rule (jobs, summed wall s):")
        print(per_rule(rounds[-1]["warm"][1]).to_string(float_format=lambda v: f"{v:.0f}"))
        figures = summarise(rounds, yardsticks)
        commands = [t for y in yardsticks for t in y.values()]
        commands += [r[0] for rnd in rounds for r in rnd.values()]
        if not args.no_tests:
            conditions.sample("before the tests")
            tests = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
            timed, printed = run(tests, base / f"round{args.repeat - 1}")
            conditions.sample("after the tests")
            closing = printed.strip().splitlines()[-1]
            print(f"  tests     {timed.wall:6.1f} s  ({closing})")
            figures.append(Figure(f"tests ({closing})", timed.wall, "s", BOUNDS["tests"]))
            commands.append(timed)
        # Other processes' share over every timed command, weighted by its time.
        others = sum(t.others * t.wall for t in commands) / sum(t.wall for t in commands)
        write_result("bench_pipeline", figures, conditions, others, own_load=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
