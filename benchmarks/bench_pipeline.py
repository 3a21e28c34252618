"""Time a full rebuild of the pipeline (the paper run by default) and say where the time
goes.

The run happens in a fresh temporary working directory (a copy of ``config.yaml``,
results under ``<tmp>/results/<run_name>/``), so it never touches ``results/paper/``
and always rebuilds everything::

    python benchmarks/bench_pipeline.py                    # paper run, 2 cores
    python benchmarks/bench_pipeline.py --cores 2 --configfile whatif/parity.yaml
    python benchmarks/bench_pipeline.py --json timings.json --keep /tmp/bench

It prints the wall time of the whole ``snakemake`` call, the time Snakemake needs to
parse the workflow and build the DAG (a dry run), and per rule the number of jobs and
their wall and CPU times from the ``benchmark:`` files. For the simulation jobs it
splits the wall time into start-up (Python, imports, numba cache), integration and
writing the trace CSV, from the timestamps of the job logs.
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

#: Target of issue 4: full rebuild of the paper run on a 2-core machine, s.
TARGET_S = 60.0


def snakemake(args, work: Path) -> tuple[float, subprocess.CompletedProcess]:
    command = [
        sys.executable,
        "-m",
        "snakemake",
        "--snakefile",
        str(ROOT / "Snakefile"),
        "--directory",
        str(work),
        *args,
    ]
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True)
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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--configfile", type=Path, nargs="*", default=[])
    parser.add_argument("--keep", type=Path, help="work here and keep the results")
    parser.add_argument("--json", type=Path, help="also write the timings here")
    args = parser.parse_args(argv)

    configfiles = [path.resolve() for path in args.configfile]
    work = args.keep or Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    if work.exists() and args.keep:
        shutil.rmtree(work / "results", ignore_errors=True)
        shutil.rmtree(work / ".snakemake", ignore_errors=True)
    work.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "config.yaml", work / "config.yaml")
    extra = ["--configfile", *map(str, configfiles)] if configfiles else []
    try:
        dag_s, _ = snakemake(["-n", "--cores", str(args.cores), *extra], work)
        total_s, _ = snakemake(["--cores", str(args.cores), *extra], work)
        out = work / "results" / run_name(configfiles)
        jobs = benchmark_table(out)
        phases = simulate_phases(out, jobs)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    per_rule = (
        jobs.groupby("rule", sort=False)
        .agg(jobs=("job", "count"), wall_s=("wall_s", "sum"), cpu_s=("cpu_s", "sum"))
        .sort_values("wall_s", ascending=False)
    )
    busy = jobs["wall_s"].sum()
    print(f"machine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f} (after the run)")
    print(f"full rebuild, --cores {args.cores}: {total_s:.1f} s (target <= {TARGET_S:.0f} s)")
    print(f"  parse + DAG (dry run): {dag_s:.1f} s")
    print(f"  job wall time, summed over {len(jobs)} jobs: {busy:.1f} s")
    print(f"  ideal with {args.cores} cores: {busy / args.cores:.1f} s; the rest is Snakemake")
    print(f"  (parsing, scheduling, job start-up outside the job) and dependency waits: "
          f"{total_s - busy / args.cores:.1f} s\n")  # fmt: skip
    print(per_rule.to_string(float_format=lambda v: f"{v:.1f}"))
    if len(phases):
        print("\nsimulation jobs, s:")
        print(phases.to_string(index=False, float_format=lambda v: f"{v:.2f}"))
    if args.json:
        args.json.write_text(
            json.dumps(
                {
                    "cores": args.cores,
                    "configfiles": [str(p) for p in configfiles],
                    "total_s": total_s,
                    "dag_s": dag_s,
                    "jobs": jobs.to_dict("records"),
                    "simulate_phases": phases.to_dict("records"),
                },
                indent=2,
                sort_keys=True,
            )
            + "\n"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
