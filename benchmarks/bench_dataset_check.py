"""Benchmark of the dataset check the pipeline runs before every run.

Run from the repository root::

    python benchmarks/bench_dataset_check.py [--shots 1000] [--samples 1200]

It writes a measured dataset of ``--shots`` shot files (``--samples`` samples each, two
sensors, the format of data/README.md) to a temporary folder and times, best of
``--repeat``:

1. the yardstick: ``pandas.read_csv`` of every shot file (what any loader does at
   least);
2. the check with an empty cache (``chain.apparatus.dataset_check.check_dataset``:
   header, cells, time steps, sample count, dead or saturated channels; a verdict per
   file stored by content hash);
3. the check with the cache filled (what a rerun of the pipeline pays): hashing the
   files and reading the verdicts.

It prints the times and their ratios to the yardstick measured in the same run, with the
load average before and after, and writes them to benchmarks/results/
(``measure.write_result``). Not a test: it asserts nothing, it reports.
"""

from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from measure import Conditions, Figure, OtherProcesses, write_result

from chain.apparatus.dataset_check import check_dataset
from chain.apparatus.metadata import write_metadata
from chain.apparatus.shot_files import write_shot_csv

BEADS = (9, 17)
INTERVAL_S = 2.0e-6


def make_dataset(folder: Path, shots: int, samples: int) -> list[Path]:
    """A valid dataset: noisy cos^6 pulses, quantised to a 12-bit +-2 V ADC."""
    rng = np.random.default_rng(2011)
    time_s = 1e-6 + INTERVAL_S * np.arange(samples)
    step = 4.0 / 2**12
    files = []
    for shot in range(shots):
        centre = time_s[samples // 3] + 1e-5 * rng.standard_normal()
        pulse = np.cos(np.clip((time_s - centre) / 5e-5, -np.pi / 2, np.pi / 2)) ** 6
        volts = np.vstack([0.3 * pulse, 0.25 * np.roll(pulse, 80)])
        volts = np.round((volts + 1e-3 * rng.standard_normal(volts.shape)) / step) * step
        name = f"shot_{shot:04d}.csv"
        write_shot_csv(folder / name, time_s, volts, BEADS)
        files.append(folder / name)
    write_metadata(
        folder,
        {
            "N": 25,
            "sensor_beads": list(BEADS),
            "sensitivity_mV_per_N": 11.24,
            "sampling_interval_s": INTERVAL_S,
            "samples": samples,
            "adc_range_V": 2.0,
            "adc_bits": 12,
            "shots": [{"file": f.name, "kind": "collision", "amplitude": 0} for f in files],
        },
    )
    return files


def best(repeat: int, work) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        work()
        times.append(time.perf_counter() - start)
    return min(times)


def figures(args, size_mb: float, yardstick: float, cold_s: float, warm_s: float) -> list:
    """What this benchmark measured, for its results file."""
    reading = f"pandas.read_csv of the {args.shots:,} files, same run"
    parse = "parsing every file, as the yardstick does"
    rerun = "hashing every file's bytes and reading the stored verdicts"
    return [
        Figure(
            f"yardstick: pandas.read_csv of {args.shots:,} shot files ({size_mb:.1f} MB)",
            yardstick,
            "s",
            "reading and parsing the files' text",
        ),
        Figure("check, empty cache", cold_s / yardstick, "x", parse, ratio_to=reading),
        Figure("check, cache filled (a rerun)", warm_s, "s", rerun),
        Figure("check, cache filled (a rerun)", warm_s / yardstick, "x", rerun, ratio_to=reading),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shots", type=int, default=1000)
    parser.add_argument("--samples", type=int, default=1200)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    base = Path(tempfile.mkdtemp(prefix="bench_dataset_check_"))
    conditions = Conditions()
    conditions.sample("before")
    try:
        folder = base / "lab"
        folder.mkdir()
        files = make_dataset(folder, args.shots, args.samples)
        cache = base / "cache"
        size = sum(f.stat().st_size for f in files) / 1e6

        def cold():
            shutil.rmtree(cache, ignore_errors=True)
            found = check_dataset(folder, cache_dir=cache)
            assert not found.problems and not found.faults, found.problems[:3]

        with OtherProcesses(interval=1.0) as others:
            yardstick = best(args.repeat, lambda: [pd.read_csv(f) for f in files])
            cold_s = best(args.repeat, cold)
            warm_s = best(args.repeat, lambda: check_dataset(folder, cache_dir=cache))
        conditions.sample("after")
        print(f"{args.shots} shots x {args.samples} samples, 2 sensors ({size:.1f} MB)")
        rows = [
            ("yardstick: pandas.read_csv of every file", yardstick),
            ("check, empty cache", cold_s),
            ("check, cache filled (a rerun)", warm_s),
        ]
        for label, seconds in rows:
            print(f"  {label:<42} {seconds:7.2f} s  {seconds / yardstick:5.2f} x yardstick")
        measured = figures(args, size, yardstick, cold_s, warm_s)
        write_result("bench_dataset_check", measured, conditions, others.share)
    finally:
        shutil.rmtree(base, ignore_errors=True)


if __name__ == "__main__":
    main()
