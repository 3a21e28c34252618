"""Reproducibility: the same bytes from every rebuild, outputs that survive an
interruption, and numerical guard rails.

Workflow tests (marked ``workflow``) take the tiny run (tests/configs/tiny.yaml, every
rule), which conftest.py's ``tiny_run`` builds once per test session with 2 cores in a
temporary copy of the checkout (Snakefile, workflow/, config.yaml; the library copied
and put on ``PYTHONPATH``) for test_workflow.py too. Every computing job writes into
its folder of the result store (``results/.store/<rule>-<label>-<key>``) and seals it
(``SHA256SUMS``, outputs read-only); the run folder ``results/tiny/`` holds copies of
the published files. Then, each in its own copy of that first build (so that they may
run at the same time, in pytest-xdist's workers),

* (a second build of every rule on 1 core under another ``PYTHONHASHSEED``, the same
  bytes in every file of ``results/tiny/`` but ``logs/`` and ``benchmarks/``, is
  test_workflow.py's; the interrupted rebuilds below run on 2 cores and require the
  first build's bytes again, in the run folder and in every entry of the store);
* look for the temporary directory, the checkout's path and today's date in the run
  folder's files and in every stored result (the intermediate files, traces and raw
  shots, are in the store only);
* interrupt a rebuild of the simulations and everything after them (their entries
  removed, as a change of the simulation code gives new ones; the jobs that do not
  read them stay stored) as soon as a simulation output is being written (Ctrl-C),
  then a forced rebuild of the tables (``--forcerun pulses``: pulses and every job
  after it write their entries again) as soon as a table is being written (a crash:
  SIGKILL); check after each that every file under its final name, in the run folder
  and in the store, is a complete one, run what the user must type, and require the
  same bytes again; then ask for the entries that a killed job left unsealed, and
  require the first build's store, entry for entry; the same with SIGTERM to
  Snakemake, then to the process group (marked ``slow``).

What Snakemake 9 (measured with 9.27, the default profile) does when interrupted, and
what to type next:

* SIGINT to the process group (Ctrl-C): kills the running jobs, deletes what they had
  written and exits 1; the outputs of every job running at the signal are marked
  incomplete (.snakemake/incomplete), also those of a job that had just sealed its
  entry, and a plain rerun then stops with IncompleteFilesException. Next:
  ``snakemake --cores 2 --rerun-incomplete``.
* SIGTERM to Snakemake alone (``kill PID``): graceful; it starts no new job, lets the
  running ones finish and exits 1. Next: ``snakemake --cores 2``.
* SIGTERM to the process group (a batch system's cancel, a container stop): the jobs
  die, Snakemake deletes their outputs and exits 1. Next: ``snakemake --cores 2``.
* SIGKILL to the process group (a crash, the OOM killer; a power loss is alike):
  nothing is cleaned up; the killed jobs' outputs are marked incomplete and the lock
  stays in .snakemake/locks, so a rerun stops with LockException (and, once unlocked,
  with IncompleteFilesException where a killed job's output is on disk). Next:
  ``snakemake --unlock``, then ``snakemake --cores 2 --rerun-incomplete``.

``--rerun-incomplete`` is harmless when nothing is incomplete, so after any interruption
``snakemake --cores 2 --rerun-incomplete`` (after ``--unlock`` if Snakemake says the
directory is locked) is the one command to remember. A file under its final name is
always complete (atomic writes); a job killed by SIGKILL may leave a hidden temporary
file (``.<name>.<random>``) beside its output, which nothing reads. A killed job's
entry is left unsealed (no ``SHA256SUMS``, one of its outputs: Snakemake sees it
missing) and is computed anew by the next run that needs it; a run whose results are
all in place (its run folder complete) needs none and leaves it so.

Unit tests: failing writes leave nothing under the final name; every workflow script
writes through the atomic writers; the integrator's bytes do not depend on the thread
count; guard rails of the library (integrator blow-up and energy drift raise; silent
sensors and unconverged fits give flagged rows; fits leave flagged rows out and refuse a
NaN in an ``ok`` row). Guard rails already tested elsewhere, not repeated here:
test_integrator (too large a step, blow-up), test_pulses (a silent sensor in
pulse_table, failures flagged not raised), test_delays (missing reference or pulse, a
flagged row left out of the fit), test_ssw (missing pulses), test_regression (too few
points give NaN, a NaN input raises), test_summary (NaN written as null).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import textwrap
import time
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from chain import default_time_step, simulate, simulate_shots, uniform_chain
from chain.analysis.delays import delay_fit_table, delay_table
from chain.analysis.pulse_rows import pulse_table
from chain.analysis.pulses import find_pulses
from chain.analysis.ssw import ssw_fit_table, ssw_table
from chain.errors import ParameterError
from chain.physics.integrator import IntegrationError
from chain.physics.theory import cos6_pulse
from chain.pipeline.run.entries import ENTRY, SUMS, discard, file_digest, files_under
from chain.traces import (
    META_COLUMNS,
    sensor_column,
    validate_traces,
    write_csv_atomic,
    write_traces,
)

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "tests" / "configs" / "tiny.yaml"
RUN = "tiny"
SNAKEMAKE = [sys.executable, "-m", "snakemake", "--configfile", str(CONFIG)]
#: Top-level entries of results/<run>/ that legitimately hold times: not compared
#: (SHA256SUMS lists the logs' digests; it must check, test_interrupted_rebuild...).
TIMED = ("logs", "benchmarks", "report.html", "SHA256SUMS")
#: The files of a store entry that are not results: the job's log and benchmark (times),
#: and the seal, compared whole (:func:`assert_store_holds_the_first_build`).
NOT_STORED_RESULTS = ("log", "benchmark.tsv", SUMS)
#: Longest a Snakemake call may take, s: a guard against a hang, far above a build's
#: minutes on a machine shared with other workers (pytest-xdist) or other work.
TIMEOUT = 1800


# ---- the workflow in a temporary directory ----------------------------------------


@dataclass(frozen=True)
class Workspace:
    base: Path  # temporary directory: work/
    work: Path  # Snakemake's working directory (a copy of the checkout, the library in src/)
    env: dict
    reference: Path  # the first build's results, for the failure messages

    @property
    def out(self) -> Path:
        return self.work / "results" / RUN

    @property
    def store(self) -> Path:
        return self.work / "results" / ".store"


def copy_workspace(ws: Workspace, base: Path, env_of_library) -> Workspace:
    """A copy of ``ws`` in ``base``: the checkout with its results and store, Snakemake's
    records and the library with its compiled kernels; copy2 keeps the files' times
    (and the stored outputs' read-only modes)."""
    work = base / "work"
    shutil.copytree(ws.work, work, symlinks=True, copy_function=shutil.copy2)
    return Workspace(base, work, env_of_library(work / "src"), ws.reference)


def snakemake(ws: Workspace, *args, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [*SNAKEMAKE, *args],
        cwd=ws.work,
        env=ws.env if env is None else env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )


def tail(result: subprocess.CompletedProcess) -> str:
    return (result.stdout + result.stderr)[-5000:]


def is_temporary(relative: Path) -> bool:
    """A temporary name of the atomic writers (``.<name>.<random>``, or a staging
    folder), which only a killed job leaves behind."""
    return any(p.startswith(".") and p != ".snakemake_timestamp" for p in relative.parts)


def result_files(out: Path) -> list[Path]:
    """Every file of results/<run>/ that must be reproducible, relative to it."""
    files = []
    for path in sorted(out.rglob("*")):
        relative = path.relative_to(out)
        if path.is_file() and relative.parts[0] not in TIMED and not is_temporary(relative):
            files.append(relative)
    return files


def temporary_files(folder: Path) -> set[str]:
    return {
        str(p.relative_to(folder))
        for p in folder.rglob(".*")
        if is_temporary(p.relative_to(folder))
    }


def digest(out: Path) -> dict[str, str]:
    return {str(f): hashlib.sha256((out / f).read_bytes()).hexdigest() for f in result_files(out)}


def differences(expected: dict, actual: dict, reference: Path, out: Path) -> list[str]:
    """Files missing, extra or changed, with the first differing line of text files."""
    lines = [f"missing: {f}" for f in sorted(set(expected) - set(actual))]
    lines += [f"extra: {f}" for f in sorted(set(actual) - set(expected))]
    for name in sorted(set(expected) & set(actual)):
        if expected[name] != actual[name]:
            lines.append(f"changed: {name}{first_difference(reference / name, out / name)}")
    return lines


def first_difference(a: Path, b: Path) -> str:
    if a.suffix not in (".csv", ".json", ".md", ".yaml"):
        return f" ({a.stat().st_size} -> {b.stat().st_size} bytes)"
    old, new = a.read_text().splitlines(), b.read_text().splitlines()
    for number, (x, y) in enumerate(zip(old, new), start=1):
        if x != y:
            return f"\n    line {number}: {x[:150]!r}\n    now    : {y[:150]!r}"
    return f" ({len(old)} -> {len(new)} lines)"


def assert_same_bytes(ws: Workspace, expected: dict, what: str) -> None:
    diffs = differences(expected, digest(ws.out), ws.reference, ws.out)
    assert not diffs, f"{what}: {len(diffs)} file(s) differ from the first build:\n" + "\n".join(
        diffs
    )


# ---- the result store ----------------------------------------------------------------


def entries(store: Path) -> dict[str, Path]:
    """The store's entries (job folders), by name."""
    return {p.name: p for p in sorted(store.iterdir()) if ENTRY.match(p.name)}


def seals(store: Path) -> dict[str, str]:
    """Entry name -> the text of its SHA256SUMS, for the sealed entries."""
    return {
        name: (entry / SUMS).read_text()
        for name, entry in entries(store).items()
        if (entry / SUMS).is_file()
    }


def listed_outputs(seal: str) -> dict[str, str]:
    """An entry's outputs (path in it -> SHA-256) as its SHA256SUMS lists them (the
    inputs it read, ``../<entry>/<file>``, left out)."""
    listed = {}
    for line in seal.splitlines():
        sha, _, name = line.partition("  ")
        if not name.startswith("../"):
            listed[name] = sha
    return listed


def store_problems(store: Path, reference: dict[str, str]) -> list[str]:
    """Where the store differs from the first build's (``reference``: its seals): an
    entry it did not have, a file under its final name that is not the first build's
    (a partial one), a seal of other content. Entries missing, or unsealed, are not
    problems here."""
    problems = []
    for name, entry in entries(store).items():
        if name not in reference:
            problems.append(f"{name}: not an entry of the first build")
            continue
        listed = listed_outputs(reference[name])
        for file in files_under(entry):
            if file in NOT_STORED_RESULTS:
                continue
            if listed.get(file) != file_digest(entry / file):
                problems.append(f"{name}/{file}: not the first build's bytes")
        if (entry / SUMS).is_file() and (entry / SUMS).read_text() != reference[name]:
            problems.append(f"{name}/{SUMS}: not the first build's")
    return problems


def downstream(store: Path, rules: tuple[str, ...]) -> list[Path]:
    """The entries of ``rules`` and of every job that read them, at any remove, as the
    seals list what each job read."""
    found = {name: entry for name, entry in entries(store).items()
             if ENTRY.match(name)["rule"] in rules}  # fmt: skip
    read = {
        name: {
            line.split("  ", 1)[1].split("/")[1] for line in seal.splitlines() if "  ../" in line
        }
        for name, seal in seals(store).items()
    }
    while more := {name for name, inputs in read.items() if inputs & set(found)} - set(found):
        found.update({name: store / name for name in more})
    return sorted(found.values())


@pytest.fixture(scope="session")
def built(tiny_run, built_once, env_of_library):
    """Run 1: the tiny run (conftest.py's ``tiny_run``, test_workflow.py's too), built
    from nothing with --cores 2 once per test session; (workspace, digest of its run
    folder, seals of its store). A copy of its run folder is kept in
    <tiny-reference>/tiny, the digest's source and the failure messages' reference, and
    of its entries' SHA256SUMS in <tiny-reference>/store. Tests that build again do so
    in a copy (:func:`rebuilt`)."""

    def keep(base: Path) -> None:
        shutil.copytree(
            tiny_run / "results" / RUN, base / RUN, ignore=shutil.ignore_patterns(*TIMED)
        )
        for name, seal in seals(tiny_run / "results" / ".store").items():
            (base / "store" / name).mkdir(parents=True)
            (base / "store" / name / SUMS).write_text(seal)

    kept = built_once("tiny-reference", keep)
    ws = Workspace(tiny_run.parent, tiny_run, env_of_library(tiny_run / "src"), kept / RUN)
    expected = digest(ws.reference)
    stored = {entry.name: (entry / SUMS).read_text() for entry in (kept / "store").iterdir()}
    assert expected == digest(ws.out)
    assert stored == seals(ws.store) and not store_problems(ws.store, stored)
    assert any(f.startswith("figures/") and f.endswith(".pdf") for f in expected), expected
    assert "summary.json" in expected and "tables/delay_fits.csv" in expected, expected
    # Intermediate files are in the store only: the virtual experiment's raw shots.
    raw = [n for n in stored if n.startswith("virtual_experiment-")]
    assert raw and all("raw/shot_0001.csv" in listed_outputs(stored[n]) for n in raw), raw
    assert not any(f.startswith(("experiment/raw/", "simulation/")) for f in expected)
    return ws, expected, stored


@pytest.fixture
def rebuilt(built, tmp_path, env_of_library):
    """(a copy of run 1's workspace, run 1's digest, run 1's seals), for a test that
    builds again."""
    ws, expected, stored = built
    return copy_workspace(ws, tmp_path, env_of_library), expected, stored


# ---- part 1: same bytes --------------------------------------------------------------


def pdf_streams(data: bytes):
    for match in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        try:
            yield zlib.decompress(match.group(1))
        except zlib.error:
            yield match.group(1)


@pytest.mark.workflow
def test_outputs_hold_no_path_and_no_date(built):
    """No absolute path (temporary directory, checkout, home) and no date of the build
    in any output of the run folder or of the store (every stored result, the
    intermediate traces and raw shots included), PDF streams inflated; no date or
    software field in PDF and PNG."""
    ws, expected, stored = built
    today = time.strftime("%Y-%m-%d").encode()
    forbidden = [str(ws.base).encode(), str(ROOT).encode(), today, b"D:" + today.replace(b"-", b"")]
    home = os.path.expanduser("~")
    if len(home) > 1:
        forbidden.append(home.encode() + b"/")
    files = [ws.out / name for name in expected]
    files += [ws.store / e / f for e, seal in stored.items() for f in listed_outputs(seal)]
    assert len(files) > len(expected)
    found = []
    for path in files:
        name, data = path.relative_to(ws.work), path.read_bytes()
        texts = [data, *pdf_streams(data)] if path.suffix == ".pdf" else [data]
        found += [f"{name}: {word!r}" for word in forbidden if any(word in t for t in texts)]
        if path.suffix == ".pdf":
            found += [f"{name}: {k!r}" for k in (b"/CreationDate", b"/ModDate") if k in data]
        if path.suffix == ".png":
            found += [f"{name}: {k!r} chunk" for k in (b"tIME", b"Software") if k in data]
    assert not found, "\n".join(found)


@pytest.mark.workflow
def test_no_nan_passes_quietly_into_the_tables(built):
    """Every ``ok`` row carries finite numbers and every flagged row a reason; a fit with
    enough points is finite; summary.json is strict JSON (NaN written as null)."""
    ws, _, _ = built
    tables = ws.out / "tables"
    checks = {
        "pulses": ["F_m_N", "T_s", "tau_s"],
        "delays": ["F_m_N", "delay_us"],
        "ssw": ["F_m_N", "ssw_N"],
    }
    for name, columns in checks.items():
        table = pd.read_csv(tables / f"{name}.csv", keep_default_na=False, na_values=["", "nan"])
        ok = table["ok"].astype(str).str.lower() == "true"
        values = table.loc[ok, columns].apply(pd.to_numeric, errors="coerce")
        assert np.isfinite(values.to_numpy(float)).all(), f"{name}.csv: NaN in an ok row"
        assert (table.loc[~ok, "reason"].astype(str).str.len() > 0).all(), name
    fits = pd.read_csv(tables / "delay_fits.csv")
    enough = fits["n_points"] >= 2
    assert np.isfinite(fits.loc[enough, ["C_us_N16", "C_stderr_us_N16"]]).all(axis=None)
    assert np.isfinite(fits.loc[fits["n_points"] >= 3, "exponent"]).all()
    ssw_fits = pd.read_csv(tables / "ssw_fits.csv")
    assert np.isfinite(ssw_fits.loc[ssw_fits["n_points"] >= 2, "slope"]).all()

    def refuse(constant):
        raise AssertionError(f"summary.json holds {constant}")

    json.loads((ws.out / "summary.json").read_text(), parse_constant=refuse)


# ---- part 3: interruption -------------------------------------------------------------

#: How an interruption is sent: signal, and to the whole process group (as a terminal's
#: Ctrl-C, a batch system or the OOM killer do) or to Snakemake alone.
INTERRUPTIONS = {
    "SIGINT-group": (signal.SIGINT, True),
    "SIGTERM-snakemake": (signal.SIGTERM, False),
    "SIGTERM-group": (signal.SIGTERM, True),
    "SIGKILL-group": (signal.SIGKILL, True),
}

#: What the user types after each interruption (the module docstring says why).
AFTERWARDS = {
    "SIGINT-group": [["--cores", "2", "--rerun-incomplete"]],
    "SIGTERM-snakemake": [["--cores", "2"]],
    "SIGTERM-group": [["--cores", "2"]],
    "SIGKILL-group": [["--unlock"], ["--cores", "2", "--rerun-incomplete"]],
}


def written_since(folders: list[Path], since_ns: int) -> bool:
    """A file of one of ``folders``, under its final or its temporary name, written
    since then."""
    for folder in folders:
        try:
            files = list(folder.iterdir())
        except FileNotFoundError:
            continue
        for entry in files:
            try:
                if entry.stat().st_mtime_ns >= since_ns:
                    return True
            except FileNotFoundError:  # renamed or deleted between listing and stat
                continue
    return False


def group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


def default_signal_handling() -> None:
    """In the child, before exec: SIGINT and SIGTERM back to their default disposition.

    An ignored signal stays ignored across fork and exec, and a shell starts a
    background job (``pytest ... &``) with SIGINT ignored; Python then installs no
    KeyboardInterrupt handler either, so Ctrl-C would not reach Snakemake or its jobs.
    """
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def interrupted_run(
    ws: Workspace, expected: dict, stored: dict, args, watched: str, how: str
) -> None:
    """Run Snakemake with ``args`` in its own session, interrupt it as ``how`` as soon
    as a file of a store folder ``watched`` (a glob under results/.store) is being
    written, and wait until it and every job it started have ended; it must have
    failed, and every file under its final name, in the run folder and in the store,
    must still be a complete one (the same bytes as run 1, or absent)."""
    signum, whole_group = INTERRUPTIONS[how]
    before = temporary_files(ws.work / "results")
    log = ws.base / f"interrupted-{how}.log"
    start = time.time_ns()
    with log.open("w") as stream:
        process = subprocess.Popen(
            [*SNAKEMAKE, *args],
            cwd=ws.work,
            env=ws.env,
            stdin=subprocess.DEVNULL,
            stdout=stream,
            stderr=subprocess.STDOUT,
            start_new_session=True,
            # However pytest was started (a terminal, CI, a background job that ignores
            # SIGINT), Snakemake must get the signals as a terminal's Ctrl-C gives them.
            preexec_fn=default_signal_handling,
        )
    try:
        deadline = time.monotonic() + TIMEOUT
        while process.poll() is None and not written_since(list(ws.store.glob(watched)), start):
            assert time.monotonic() < deadline, f"nothing written to {watched}/"
            time.sleep(0.02)
        assert process.poll() is None, f"the run ended before it could be interrupted ({how})"
        if whole_group:
            os.killpg(process.pid, signum)
        else:
            process.send_signal(signum)
        status = process.wait(timeout=TIMEOUT)
        deadline = time.monotonic() + 30
        while group_alive(process.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not group_alive(process.pid), f"jobs still running after Snakemake exited ({how})"
    finally:
        if group_alive(process.pid):
            os.killpg(process.pid, signal.SIGKILL)
        if process.poll() is None:
            process.wait()
    assert status != 0, f"the interrupted run exited 0 ({how}):\n{log.read_text()[-3000:]}"

    partial = [f for f, h in digest(ws.out).items() if expected.get(f) != h]
    assert not partial, f"incomplete files under their final names after {how}: {partial}"
    problems = store_problems(ws.store, stored)
    assert not problems, f"incomplete stored files after {how}:\n" + "\n".join(problems)
    if signum != signal.SIGKILL:  # only SIGKILL gives a job no chance to clean up
        left = temporary_files(ws.work / "results") - before
        assert not left, f"temporary files left after {how}: {left}"


def resume(ws: Workspace, how: str) -> None:
    """Type what the user must type after ``how``; every command must succeed."""
    commands = AFTERWARDS[how]
    if how == "SIGKILL-group":
        # The lock stays: even with --rerun-incomplete, Snakemake refuses to start.
        # (A plain rerun may stop earlier, at the incomplete files.)
        locked = snakemake(ws, "--cores", "2", "--rerun-incomplete")
        assert locked.returncode != 0, tail(locked)
        assert "LockException" in tail(locked) and "--unlock" in tail(locked), tail(locked)
    for command in commands:
        result = snakemake(ws, *command)
        assert result.returncode == 0, f"snakemake {' '.join(command)}:\n{tail(result)}"


def assert_store_holds_the_first_build(ws: Workspace, stored: dict, what: str) -> None:
    problems = store_problems(ws.store, stored)
    assert not problems, f"{what}: the store differs from the first build's:\n" + "\n".join(
        problems
    )


@pytest.mark.workflow
@pytest.mark.parametrize(
    ("first", "second"),
    [
        pytest.param("SIGINT-group", "SIGKILL-group", marks=pytest.mark.heavy(cpu_s=31)),
        pytest.param(
            "SIGTERM-snakemake",
            "SIGTERM-group",
            marks=[pytest.mark.slow, pytest.mark.heavy(cpu_s=22)],
        ),
    ],
    ids=["ctrl-c-then-crash", "sigterm-snakemake-then-group"],
)
def test_interrupted_rebuild_resumes_to_the_same_bytes(rebuilt, first, second):
    """A rebuild of the simulations and every job after them (their entries and the run
    folder removed, as a change of the simulation code leaves them to compute)
    interrupted (``first``) while the simulations are being written, then the user's
    command; a forced rebuild of the tables (``--forcerun pulses``: pulses and every job
    after it write their entries again) interrupted (``second``) while a table is being
    written, then the user's command: the same bytes as an uninterrupted build, in the
    run folder and in every entry of the store, and after each interruption every file
    under its final name is a complete one. Each interruption hits a rebuild of the
    jobs that write the watched folders, so that the run cannot end before they are
    written, whatever the machine's speed.

    A killed job leaves its entry unsealed; the user's command computes it again where
    the run needs it, and leaves it where the run folder is complete without it (the
    forced rebuild's): asked for, it is computed to the same bytes, and then every
    entry of the first build is there, sealed as then."""
    ws, expected, stored = rebuilt
    for entry in downstream(ws.store, ("simulate",)):
        discard(entry)
    shutil.rmtree(ws.out)
    interrupted_run(ws, expected, stored, ["--cores", "2"], "simulate-*/simulation", first)
    resume(ws, first)
    assert_same_bytes(ws, expected, f"interrupted ({first}) and resumed")
    assert_checksums_hold(ws.out)
    assert_store_holds_the_first_build(ws, stored, f"interrupted ({first}) and resumed")

    forced = ["--forcerun", "pulses", "--cores", "2"]
    interrupted_run(ws, expected, stored, forced, "*/tables", second)
    resume(ws, second)
    assert_same_bytes(ws, expected, f"interrupted ({second}) and resumed")
    assert_checksums_hold(ws.out)
    assert_store_holds_the_first_build(ws, stored, f"interrupted ({second}) and resumed")

    unsealed = [entry for name, entry in entries(ws.store).items() if name not in seals(ws.store)]
    if unsealed:
        asked = [str((entry / SUMS).relative_to(ws.work)) for entry in unsealed]
        result = snakemake(ws, "--cores", "2", "--rerun-incomplete", *asked)
        assert result.returncode == 0, tail(result)
    assert seals(ws.store) == stored, "the store's entries differ from the first build's"
    assert_store_holds_the_first_build(ws, stored, "the unsealed entries computed")
    for entry in entries(ws.store).values():
        assert_checksums_hold(entry)


def assert_checksums_hold(folder: Path) -> None:
    """A SHA256SUMS (the run folder's, where a run left one: each run that ran a job;
    after a SIGKILL none until then; or a store entry's, which lists its outputs and the
    stored inputs it read) lists its files as they are."""
    if (folder / SUMS).exists():
        check = subprocess.run(
            ["sha256sum", "-c", "--quiet", SUMS], cwd=folder, capture_output=True, text=True
        )
        assert check.returncode == 0, f"{folder}:\n{check.stdout}{check.stderr}"


# ---- part 3: atomic writes (unit) ---------------------------------------------------


class Unprintable:
    def __str__(self):
        raise ValueError("cannot be serialised")


def listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def test_a_failing_table_write_leaves_no_file(tmp_path):
    """A table that cannot be serialised (its last value raises) leaves neither a file
    under the final name nor a temporary file."""
    table = pd.DataFrame({"a": [1.0, 2.0], "b": ["x", Unprintable()]})
    with pytest.raises(ValueError, match="cannot be serialised"):
        write_csv_atomic(table, tmp_path / "table.csv")
    assert listing(tmp_path) == []


def test_a_write_failing_midway_keeps_the_previous_file(tmp_path, monkeypatch):
    """The CSV text failing after the first rows are out: the old file stays as it was."""
    import chain.csv_text

    target = tmp_path / "table.csv"
    target.write_text("old,content\n")

    def half_then_fail(table):
        yield "a,b\n1,2\n"
        raise OSError("disk full")

    monkeypatch.setattr(chain.csv_text, "csv_chunks", half_then_fail)
    with pytest.raises(OSError, match="disk full"):
        write_csv_atomic(pd.DataFrame({"a": [1], "b": [2]}), target)
    assert listing(tmp_path) == ["table.csv"]
    assert target.read_text() == "old,content\n"


def test_an_interruption_as_the_temporary_file_appears_leaves_no_file(tmp_path, monkeypatch):
    """SIGTERM the moment the temporary file exists (the interrupted rebuilds signal as
    soon as a file of the watched folder appears): the job ends as a SIGTERM handler
    ends it (SystemExit, raised at the next bytecode), and neither the temporary nor a
    final file is left. The creating call raises it itself, so no clock decides where
    it lands (``tempfile.mkstemp``, which made the file before its name was known,
    failed this)."""
    import chain.atomic

    real_open = os.open

    def open_then_interrupted(file, flags, *args, **kwargs):
        made = real_open(file, flags, *args, **kwargs)
        if flags & os.O_CREAT and Path(file).name.startswith(".t.csv."):
            os.close(made)
            raise SystemExit(128 + signal.SIGTERM)
        return made

    monkeypatch.setattr(chain.atomic.os, "open", open_then_interrupted)
    with pytest.raises(SystemExit):
        write_csv_atomic(pd.DataFrame({"a": [1.0], "b": [2.0]}), tmp_path / "t.csv")
    monkeypatch.undo()
    assert listing(tmp_path) == []


def test_atomic_tables_get_ordinary_permissions(tmp_path):
    """Not the 0600 of a temporary file: others may read the results like any file."""
    umask = os.umask(0o022)
    try:
        write_csv_atomic(pd.DataFrame({"a": [1]}), tmp_path / "t.csv")
    finally:
        os.umask(umask)
    assert (tmp_path / "t.csv").stat().st_mode & 0o777 == 0o644


def test_an_invalid_trace_table_writes_nothing(tmp_path):
    with pytest.raises(ValueError):
        write_traces(pd.DataFrame({"t_s": [0.0, 1.0]}), tmp_path / "traces.csv")
    assert listing(tmp_path) == []


def test_a_failing_figure_save_leaves_no_file(tmp_path, monkeypatch):
    """save_figure writes PDF and PNG through temporary names: a savefig raising after
    writing part of the file leaves nothing under the final names."""
    from matplotlib.figure import Figure

    from chain.report.figures.style import save_figure

    fig = Figure()
    fig.add_subplot().plot([0, 1], [1, 0])

    def partial_then_fail(path, **kwargs):
        Path(path).write_bytes(b"%PDF-1.4 partial")
        raise RuntimeError("renderer failed")

    monkeypatch.setattr(fig, "savefig", partial_then_fail)
    with pytest.raises(RuntimeError, match="renderer failed"):
        save_figure(fig, tmp_path / "fig")
    assert listing(tmp_path) == []


def test_a_failing_summary_leaves_no_partial_file(tmp_path, monkeypatch):
    import chain.report.numbers.summary
    import chain.report.text.markdown

    def fail(summary):
        raise RuntimeError("bad summary")

    chain.report.numbers.summary.write_summary_json({"run_name": "x"}, tmp_path / "s.json")
    monkeypatch.setattr(chain.report.text.markdown, "summary_markdown", fail)
    with pytest.raises(RuntimeError, match="bad summary"):
        chain.report.text.markdown.write_summary_markdown(tmp_path / "s.json", tmp_path / "s.md")
    # The JSON is complete on its own; the Markdown never appears, even partly.
    assert listing(tmp_path) == ["s.json"]
    assert json.loads((tmp_path / "s.json").read_text()) == {"run_name": "x"}


#: A workflow script's job, terminated (SIGTERM) in the middle of writing its table.
TERMINATED_JOB = textwrap.dedent(
    """
    import os, signal, sys, types
    import pandas as pd
    sys.path.insert(0, sys.argv[1])
    import chain.csv_text
    from chain.atomic import write_csv_atomic
    folder = sys.argv[2]
    if sys.argv[3] == "start":
        import _logging
        _logging.start(types.SimpleNamespace(
            log=[os.path.join(folder, "job.log")], rule="demo", input=[], output=[]))
    def chunks(table):
        yield "a,b\\n"
        os.kill(os.getpid(), signal.SIGTERM)
        yield "1,2\\n"
    chain.csv_text.csv_chunks = chunks
    write_csv_atomic(pd.DataFrame({"a": [1], "b": [2]}), os.path.join(folder, "t.csv"))
    """
)


@pytest.mark.parametrize("handler", [True, False], ids=["scripts", "bare-python"])
def test_a_terminated_job_leaves_no_temporary_file(tmp_path, handler):
    """The scripts' _logging.start turns SIGTERM into SystemExit, so the atomic writer
    deletes its temporary file; bare Python dies on the spot and leaves it."""
    result = subprocess.run(
        [
            sys.executable,
            "-c",
            TERMINATED_JOB,
            str(ROOT / "workflow" / "scripts"),
            str(tmp_path),
            "start" if handler else "bare",
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    files = [f for f in listing(tmp_path) if f != "job.log"]
    assert "t.csv" not in files
    if handler:
        assert result.returncode == 128 + signal.SIGTERM, result.stderr
        assert files == []
    else:
        assert result.returncode == -signal.SIGTERM
        assert len(files) == 1 and files[0].startswith(".t.csv.")


#: Ways to write a file that bypass the atomic writers.
DIRECT_WRITES = re.compile(
    r"\.to_csv\(|\.savefig\(|\.write_text\(|\.write_bytes\(|json\.dump|np\.save|"
    r"\.to_parquet\(|\bopen\([^)]*[\"'][wax]"
)


@pytest.mark.parametrize(
    "script",
    sorted(p.name for p in (ROOT / "workflow" / "scripts").glob("*.py") if p.name != "_logging.py"),
)
def test_workflow_scripts_write_through_atomic_writers(script):
    """Outputs go through write_csv_atomic, write_traces, save_figure, write_summary_json or
    run_virtual_experiment (temporary name, then rename); only _logging opens its log."""
    source = (ROOT / "workflow" / "scripts" / script).read_text()
    direct = [line.strip() for line in source.splitlines() if DIRECT_WRITES.search(line)]
    assert not direct, f"{script} writes directly: {direct}"


# ---- part 1: thread count (unit) -----------------------------------------------------


def test_integrator_bytes_do_not_depend_on_the_thread_count():
    numba = pytest.importorskip("numba")
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one thread only")
    speeds = np.geomspace(0.05, 1.0, 6)
    previous = numba.get_num_threads()
    runs = []
    try:
        for threads in (1, numba.config.NUMBA_NUM_THREADS):
            numba.set_num_threads(threads)
            runs.append(simulate(uniform_chain(12), speeds, speeds, duration=4e-4))
    finally:
        numba.set_num_threads(previous)
    for name in ("contact_force", "bead_velocity", "kinetic_energy", "potential_energy"):
        np.testing.assert_array_equal(getattr(runs[0], name), getattr(runs[1], name), name)


# ---- part 4: guard rails (unit) ------------------------------------------------------


def test_energy_drift_above_threshold_raises():
    """A finite but inaccurate run (20x the default step) is refused by its drift."""
    model = uniform_chain(10)
    coarse = 20 * default_time_step(model, 1.0)
    drifted = simulate(model, 1.0, duration=3e-4, dt=coarse, max_energy_drift=1.0)
    assert np.isfinite(drifted.contact_force).all() and drifted.energy_drift[0] > 1e-8
    with pytest.raises(IntegrationError, match=r"energy drift .* exceeds max_energy_drift"):
        simulate(model, 1.0, duration=3e-4, dt=coarse, max_energy_drift=1e-9)
    # The pipeline's entry point (workflow/scripts/simulate.py) raises too: no output.
    with pytest.raises(IntegrationError, match="energy drift"):
        simulate_shots(
            model, [1.0], [3, 8], model_name="m", duration=3e-4, dt=coarse, max_energy_drift=1e-9
        )


TIME_S = np.arange(0.0, 1e-3, 1e-6)
BEADS = (9, 17)


def shot_table(signals, *, noise=0.0, seed=0) -> pd.DataFrame:
    """Trace table of shots (kind, amplitude, S1 signal, S2 signal), offset 1 N."""
    rng = np.random.default_rng(seed)
    frames = []
    for shot, (kind, amplitude, s1, s2) in enumerate(signals):
        frame = pd.DataFrame(
            {
                "source": "experiment",
                "model": "rig",
                "N": 25,
                "shot": shot,
                "kind": kind,
                "amplitude": amplitude,
                "v0_left_m_s": np.nan,
                "v0_right_m_s": np.nan,
                "t_s": TIME_S,
            }
        )
        for bead, signal_N in zip(BEADS, (s1, s2)):
            frame[sensor_column(bead)] = 1.0 + signal_N + rng.normal(0.0, noise, TIME_S.size)
        frames.append(frame[[*META_COLUMNS, *map(sensor_column, BEADS)]])
    return validate_traces(pd.concat(frames, ignore_index=True))


def crossing_shots(force=100.0, tau=20e-6, amplitudes=(0, 1)):
    """A collision and a reference shot per amplitude, pulses well apart."""
    shots = []
    for k in amplitudes:
        f = force * (1 + k)
        one = cos6_pulse(TIME_S, f, 250e-6, tau)
        two = cos6_pulse(TIME_S, 0.97 * f, 650e-6, tau)
        shots.append(("collision", k, one + two, one + two))
        shots.append(("reference", k, one, cos6_pulse(TIME_S, f, 655e-6, tau)))
    return shots


def all_flagged(table: pd.DataFrame, value_columns) -> None:
    assert len(table) and not table["ok"].any(), table
    assert table[list(value_columns)].isna().all(axis=None)
    assert (table["reason"].str.len() > 0).all()


def test_silent_sensors_give_flagged_rows_all_the_way_to_the_fits():
    """Both sensors record only an offset (a dead channel, a missed trigger): every
    pulse, delay and SSW row is flagged with a reason and NaN values, and the fits have
    0 points and NaN values, with no exception and no number made up."""
    flat = np.zeros_like(TIME_S)
    traces = shot_table([(k, a, flat, flat) for k, a, *_ in crossing_shots()])
    pulses = pulse_table(traces, estimators=("fit_full", "peak"))
    all_flagged(pulses, ["F_m_N", "T_s"])
    delays = delay_table(pulses)
    all_flagged(delays, ["F_m_N", "delay_us"])
    fits = delay_fit_table(delays)
    assert (fits["n_points"] == 0).all() and fits["C_us_N16"].isna().all()
    ssw = ssw_table(traces, pulses)
    all_flagged(ssw, ["ssw_N"])
    ssw_fits = ssw_fit_table(ssw)
    assert (ssw_fits["n_points"] == 0).all() and ssw_fits["slope"].isna().all()


def test_noise_only_signals_have_no_pulse():
    """Gaussian noise alone, over many seeds, never gives a pulse (the 8-sigma threshold
    is meant to stop the largest of 10^4 samples)."""
    detected = []
    for seed in range(40):
        noise = 1.0 + np.random.default_rng(seed).normal(0.0, 0.1, TIME_S.size)
        if find_pulses(TIME_S, noise):
            detected.append(seed)
    assert not detected, f"pulses found in noise alone for seeds {detected}"


def test_unconverged_fits_are_flagged_and_left_out(monkeypatch):
    """curve_fit failing on every pulse: the fit_full rows are flagged 'fit did not
    converge', their delays flagged, their fits empty; the peak estimator, which does
    not fit, is unaffected."""
    import scipy.optimize

    def no_convergence(*args, **kwargs):
        raise RuntimeError("Optimal parameters not found: maxfev reached")

    traces = shot_table(crossing_shots())
    # chain.analysis.pulses imports curve_fit from scipy.optimize when it fits.
    monkeypatch.setattr(scipy.optimize, "curve_fit", no_convergence)
    pulses = pulse_table(traces, estimators=("fit_full", "peak"))
    fitted = pulses[pulses["estimator"] == "fit_full"]
    all_flagged(fitted, ["F_m_N", "T_s"])
    assert fitted["reason"].str.contains("fit did not converge").all()
    assert pulses.loc[pulses["estimator"] == "peak", "ok"].all()
    delays = delay_table(pulses)
    assert not delays.loc[delays["estimator"] == "fit_full", "ok"].any()
    assert delays.loc[delays["estimator"] == "peak", "ok"].all()
    fits = delay_fit_table(delays).set_index("estimator")
    assert (fits.loc["fit_full", "n_points"] == 0).all()
    assert (fits.loc["peak", "n_points"] > 0).all()


def test_fits_ignore_flagged_rows_and_refuse_nan_in_ok_rows():
    """Flagged rows, NaN or not, change nothing in the delay and SSW fits (the result is
    the fit of the ok rows alone, to the bit); a NaN in an ``ok`` row is an error, not
    a NaN fit."""
    forces = np.geomspace(10.0, 1000.0, 6)
    delays = pd.DataFrame(
        {
            "source": "simulation",
            "model": "m",
            "N": 25,
            "estimator": "fit_full",
            "F_m_N": forces,
            "delay_us": -40.0 * forces ** (-1 / 6),
            "ok": True,
        }
    )
    junk = delays.iloc[:3].assign(ok=False, F_m_N=[np.nan, 5.0, -1.0], delay_us=[1.0, np.nan, 1e9])
    pd.testing.assert_frame_equal(
        delay_fit_table(pd.concat([delays, junk], ignore_index=True)), delay_fit_table(delays)
    )
    with pytest.raises(ParameterError, match="finite"):
        delay_fit_table(delays.assign(delay_us=[np.nan, *delays["delay_us"][1:]]))

    ssw = pd.DataFrame(
        {
            "source": "simulation",
            "model": "m",
            "N": 25,
            "method": "residual",
            "F_m_N": forces,
            "ssw_N": 0.04 * forces,
            "ssw_err_N": 0.004 * forces,
            "ssw_sys_N": 0.002 * forces,
            "resolved": True,
            "ok": True,
        }
    )
    junk = ssw.iloc[:2].assign(ok=False, ssw_N=[np.nan, 1e6], ssw_err_N=[np.nan, 0.0])
    pd.testing.assert_frame_equal(
        ssw_fit_table(pd.concat([ssw, junk], ignore_index=True)), ssw_fit_table(ssw)
    )
    assert math.isclose(ssw_fit_table(ssw)["slope"].iloc[0], 0.04, rel_tol=1e-12)
    with pytest.raises(ParameterError, match="finite"):
        ssw_fit_table(ssw.assign(ssw_N=[*ssw["ssw_N"][:-1], np.nan]))
