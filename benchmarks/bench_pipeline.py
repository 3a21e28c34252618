"""Time a full rebuild of the pipeline (the paper run by default) and say where the time
goes.

The run happens in a temporary copy of the checkout (the files git tracks, plus the
numba cache of ``src/chain`` unless ``--fresh``), whose ``src`` the jobs import: it
never touches ``results/paper/`` or the checkout's sources, and always rebuilds
everything::

    python benchmarks/bench_pipeline.py                    # paper run, 2 cores
    python benchmarks/bench_pipeline.py --cores 2 --configfile whatif/parity.yaml
    python benchmarks/bench_pipeline.py --json timings.json --keep /tmp/bench
    python benchmarks/bench_pipeline.py --fresh     # also: numba cache empty

It prints the wall time of the whole ``snakemake`` call, the time Snakemake needs to
parse the workflow and build the DAG (a dry run), and per rule the number of jobs and
their wall and CPU times from the ``benchmark:`` files. For the simulation jobs it
splits the wall time into start-up (Python, imports, numba cache), integration and
writing the trace CSV, from the timestamps of the job logs.

Then it **restyles one figure**: a line is added to the copy's
``src/chain/report/figures/fig4_delay_vs_force.py`` (Snakemake reruns on content, not on a
newer modification time alone) and the ``snakemake`` call that follows is timed, with
the jobs it reran. ``--fresh`` first rebuilds with the numba cache empty, as a fresh
clone does, then rebuilds again with the cache it filled.

``--imports`` finally rebuilds once more on one core with ``PYTHONPROFILEIMPORTTIME``
(``python -X importtime`` for every job) and prints, per rule, the seconds its jobs
spent importing modules, and how much of it went to the heavy packages (cumulative:
a package's figure includes what it was first to load, so scipy.signal includes
scipy.stats). Import timing slows imports a little; read the shares.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from datetime import datetime
from pathlib import Path

import pandas as pd
import yaml

ROOT = Path(__file__).resolve().parents[1]

#: Targets of issue 14 on a 2-core machine, s: full rebuild with a warm numba cache, from
#: a fresh clone (numba cache empty), restyling one figure, the slowest figure job.
TARGET_S = {"rebuild": 25.0, "fresh": 60.0, "restyle": 3.0, "figure_job": 3.0}

#: The figure module the restyle step "edits", and the rule that draws it.
RESTYLED = ("src/chain/report/figures/fig4_delay_vs_force.py", "fig4_delay_vs_force")


def snakemake(args, work: Path) -> tuple[float, subprocess.CompletedProcess]:
    """Run snakemake in the copy ``work``, its jobs importing the copy's library."""
    command = [sys.executable, "-m", "snakemake", *args]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(work / "src"), os.environ.get("PYTHONPATH", "")]),
    }
    start = time.perf_counter()
    result = subprocess.run(command, cwd=work, capture_output=True, text=True, env=env)
    elapsed = time.perf_counter() - start
    if result.returncode != 0:
        sys.stderr.write(result.stdout[-4000:] + result.stderr[-4000:])
        raise SystemExit(f"snakemake failed: {' '.join(command)}")
    return elapsed, result


def run_name(configfiles: list[Path]) -> str:
    name = yaml.safe_load((ROOT / "config.yaml").read_text())["run_name"]
    for path in configfiles:
        name = (yaml.safe_load(path.read_text()) or {}).get("run_name", name)
    return name


def benchmark_table(out: Path) -> pd.DataFrame:
    """One row per job with a benchmark file: rule, job, wall s, CPU s, max RSS MB."""
    rows = []
    for path in sorted((out / "benchmarks").rglob("*.tsv")):
        table = pd.read_csv(path, sep="\t")
        relative = path.relative_to(out / "benchmarks")
        group = relative.parts[0] if len(relative.parts) > 1 else relative.stem
        rule = {"tables": relative.stem, "figures": relative.stem}.get(group, group)
        rows.append(
            {
                "rule": rule,
                "job": str(relative.with_suffix("")),
                "wall_s": float(table["s"].iloc[-1]),
                "cpu_s": float(table["cpu_time"].iloc[-1]),
                "max_rss_MB": float(table["max_rss"].iloc[-1]),
            }
        )
    return pd.DataFrame(rows)


_STAMP = re.compile(r"^(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d,\d{3}) INFO [^:]+: (.*)$")


def simulate_phases(out: Path, jobs: pd.DataFrame) -> pd.DataFrame:
    """Start-up / integration / CSV writing of each simulation job, s (from its log)."""
    rows = []
    for path in sorted((out / "logs" / "simulate").glob("*.log")):
        stamps = []
        for line in path.read_text().splitlines():
            match = _STAMP.match(line)
            if match:
                when = datetime.strptime(match[1], "%Y-%m-%d %H:%M:%S,%f").timestamp()
                stamps.append((when, match[2]))
        marks = {text.split(" ")[0]: when for when, text in stamps}
        if not {"inputs:", "dt", "done"} <= set(marks):
            continue
        wall = jobs.loc[jobs["job"] == f"simulate/{path.stem}", "wall_s"]
        integrate = marks["dt"] - marks["inputs:"]
        write = marks["done"] - marks["dt"]
        total = float(wall.iloc[0]) if len(wall) else float("nan")
        rows.append(
            {
                "job": path.stem,
                "wall_s": total,
                "startup_s": total - integrate - write,
                "integrate_s": integrate,
                "write_csv_s": write,
            }
        )
    return pd.DataFrame(rows)


def copy_checkout(work: Path, numba_cache: bool) -> None:
    """The files git tracks into ``work`` (and the numba cache files of the package,
    with their modification times, which numba's index checks)."""
    tracked = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split("\0")
    cached = ROOT.glob("src/chain/**/__pycache__/*.nb[ic]") if numba_cache else []
    for path in [ROOT / name for name in tracked if name] + list(cached):
        if path.is_file():
            target = work / path.relative_to(ROOT)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(path, target)


def restyle(work: Path, cores: int, extra: list[str]) -> tuple[float, list[str]]:
    """Edit the restyled figure's module in the copy and rerun. Returns the wall time
    of the run, s, and the rules it ran."""
    with open(work / RESTYLED[0], "a") as module:
        module.write("# restyled by bench_pipeline.py\n")
    elapsed, result = snakemake(["--cores", str(cores), *extra], work)
    ran = re.findall(r"^(?:local)?rule (\w+):", result.stdout + result.stderr, re.MULTILINE)
    return elapsed, ran


#: Packages whose import cost --imports shows per rule.
HEAVY_IMPORTS = ("snakemake", "pandas", "numba", "matplotlib.figure", "scipy.signal",
                 "scipy.stats", "scipy.optimize", "scipy.interpolate")  # fmt: skip

_RULE_LINE = re.compile(r"^\s*(?:local)?rule (\w+):")
_IMPORT_LINE = re.compile(r"^import time:\s+\d+ \|\s+(\d+) \|( *)(\S+)$")


def import_table(work: Path, extra: list[str]) -> pd.DataFrame:
    """Per rule: jobs, seconds of imports (top-level, summed), seconds per heavy package.

    A forced rebuild on one core, so that each job's import report follows the
    ``rule <name>:`` line Snakemake writes before it."""
    env_name = "PYTHONPROFILEIMPORTTIME"
    os.environ[env_name] = "1"
    try:
        _, done = snakemake(["--cores", "1", "--forceall", *extra], work)
    finally:
        del os.environ[env_name]
    rows: dict[str, dict] = {}
    rule = "(snakemake itself)"
    for line in done.stderr.splitlines():
        header = _RULE_LINE.match(line)
        if header:
            rule = header.group(1)
            row = rows.setdefault(rule, {"rule": rule, "jobs": 0, "imports_s": 0.0})
            row["jobs"] += 1
            continue
        timing = _IMPORT_LINE.match(line)
        if not timing:
            continue
        seconds, indent, module = int(timing.group(1)) / 1e6, timing.group(2), timing.group(3)
        row = rows.setdefault(rule, {"rule": rule, "jobs": 0, "imports_s": 0.0})
        if indent == " ":  # top level: "| name" (one space after the bar)
            row["imports_s"] += seconds
        if module in HEAVY_IMPORTS:
            row[module] = row.get(module, 0.0) + seconds
    table = pd.DataFrame(list(rows.values())).fillna(0.0)
    columns = ["rule", "jobs", "imports_s", *[m for m in HEAVY_IMPORTS if m in table]]
    return table[columns].sort_values("imports_s", ascending=False)


def report(args, timings: dict, jobs: pd.DataFrame, phases: pd.DataFrame) -> None:
    """Print the figures of one benchmark run."""
    per_rule = (
        jobs.groupby("rule", sort=False)
        .agg(jobs=("job", "count"), wall_s=("wall_s", "sum"), cpu_s=("cpu_s", "sum"))
        .sort_values("wall_s", ascending=False)
    )
    busy = jobs["wall_s"].sum()
    total_s = timings["total_s"]
    print(f"machine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} (after the run)")
    if "fresh_s" in timings:
        print(f"rebuild, numba cache empty (fresh clone), --cores {args.cores}: "
              f"{timings['fresh_s']:.1f} s (target <= {TARGET_S['fresh']:.0f} s)")  # fmt: skip
    print(f"full rebuild, warm numba cache, --cores {args.cores}: {total_s:.1f} s "
          f"(target <= {TARGET_S['rebuild']:.0f} s)")  # fmt: skip
    print(f"  parse + DAG (dry run): {timings['dag_s']:.1f} s")
    print(f"  job wall time, summed over {len(jobs)} jobs: {busy:.1f} s")
    print(f"  ideal with {args.cores} cores: {busy / args.cores:.1f} s; the rest is Snakemake")
    print(f"  (parsing, scheduling, job start-up outside the job) and dependency waits: "
          f"{total_s - busy / args.cores:.1f} s")  # fmt: skip
    figures = jobs[jobs["job"].str.startswith("figures/")]
    slowest = figures.loc[figures["wall_s"].idxmax()]
    print(f"slowest figure job: {slowest['rule']} {slowest['wall_s']:.1f} s "
          f"(target <= {TARGET_S['figure_job']:.0f} s)")  # fmt: skip
    reran = ", ".join(timings["restyle_rules"])
    print(f"restyle {RESTYLED[0]}: snakemake call {timings['restyle_s']:.1f} s, reran "
          f"{reran}; the {RESTYLED[1]} job {timings['restyle_job_s']:.1f} s "
          f"(target <= {TARGET_S['restyle']:.0f} s)\n")  # fmt: skip
    print(per_rule.to_string(float_format=lambda v: f"{v:.1f}"))
    if len(phases):
        print("\nsimulation jobs, s:")
        print(phases.to_string(index=False, float_format=lambda v: f"{v:.2f}"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--configfile", type=Path, nargs="*", default=[])
    parser.add_argument("--keep", type=Path, help="work here and keep the results")
    parser.add_argument("--json", type=Path, help="also write the timings here")
    parser.add_argument("--fresh", action="store_true", help="also rebuild, numba cache empty")
    parser.add_argument(
        "--imports", action="store_true", help="also: import time per rule (one-core rebuild)"
    )
    args = parser.parse_args(argv)

    configfiles = [path.resolve() for path in args.configfile]
    work = args.keep or Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    if work.exists() and args.keep:
        shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True, exist_ok=True)
    copy_checkout(work, numba_cache=not args.fresh)
    extra = ["--configfile", *map(str, configfiles)] if configfiles else []
    timings = {"cores": args.cores, "configfiles": [str(p) for p in configfiles]}
    try:
        timings["dag_s"], _ = snakemake(["-n", "--cores", str(args.cores), *extra], work)
        if args.fresh:
            timings["fresh_s"], _ = snakemake(["--cores", str(args.cores), *extra], work)
        forced = ["--forceall"] if args.fresh else []
        timings["total_s"], _ = snakemake(["--cores", str(args.cores), *forced, *extra], work)
        out = work / "results" / run_name(configfiles)
        jobs = benchmark_table(out)
        phases = simulate_phases(out, jobs)
        timings["restyle_s"], timings["restyle_rules"] = restyle(work, args.cores, extra)
        again = benchmark_table(out)
        timings["restyle_job_s"] = float(again.loc[again["rule"] == RESTYLED[1], "wall_s"].iloc[0])
        imports = import_table(work, extra) if args.imports else None
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    report(args, timings, jobs, phases)
    if imports is not None:
        jobs_only = imports[imports["jobs"] > 0]
        print("\nimports per rule (one-core rebuild, PYTHONPROFILEIMPORTTIME), s:")
        print(imports.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
        print(f"all jobs: {jobs_only['imports_s'].sum():.1f} s of imports in "
              f"{int(jobs_only['jobs'].sum())} jobs")  # fmt: skip
        timings["imports"] = imports.to_dict("records")
    if args.json:
        timings |= {"jobs": jobs.to_dict("records"), "simulate_phases": phases.to_dict("records")}
        args.json.write_text(json.dumps(timings, indent=2, sort_keys=True) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
