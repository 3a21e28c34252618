"""The run folder (``results/<run_name>``): plain copies of what a run shows, each
checked against the digest stored with it, with the logs and benchmark files of every
job they come from, and ``SHA256SUMS`` last.

The jobs of a run are the entries its files come from and, through the inputs each
entry's ``SHA256SUMS`` lists (``../<entry>/<file>``), every entry upstream of them:
their logs go to ``logs/<rule>/<label>.log``, Snakemake's benchmark files to
``benchmarks/<rule>/<label>.tsv``.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from collections.abc import Sequence
from pathlib import Path

from chain.atomic import atomic_output
from chain.pipeline.provenance.checksums import CHUNK, write_checksums
from chain.pipeline.run.entries import ENTRY, SUMS, DamagedEntry, discard, entry_of, read_sums

#: The run folder's own records, rewritten whole by every copy.
RECORDS = ("logs", "benchmarks")


def fill_run_folder(sources: Sequence[str], targets: Sequence[str], sums: str) -> list[str]:
    """Copy each stored file of ``sources`` to its ``targets`` path (same order), checked
    against its entry's digest (a mismatch discards the entry and raises
    :class:`DamagedEntry`), copy the logs and benchmarks of the jobs upstream, and
    write ``sums`` (the run folder's ``SHA256SUMS``) listing every file of the folder.
    Returns the console's lines (what was copied).

    Parameters
    ----------
    sources : sequence of str
        Stored outputs (files in entries of the store).
    targets : sequence of str
        Their paths in the run folder.
    sums : str
        ``<run folder>/SHA256SUMS``.
    """
    folder = Path(sums).parent
    for name in RECORDS:
        shutil.rmtree(folder / name, ignore_errors=True)
    # A file an earlier run of another config put in one of the folders the run shows
    # (a study switched off since) goes: the folder shows this run alone.
    wanted = {os.path.normpath(t) for t in targets}
    shown = {Path(t).relative_to(folder).parts[0] for t in targets if Path(t).parent != folder}
    for path in (p for name in shown for p in (folder / name).rglob("*") if p.is_file()):
        if os.path.normpath(path) not in wanted:
            path.unlink()
    digests = {}
    for source, target in zip(sources, targets, strict=True):
        digests[os.path.normpath(target)] = _copy_checked(Path(source), Path(target))
    entries = upstream({entry_of(source) for source in sources})
    for entry in entries:
        _copy_records(entry, folder)
    write_checksums(folder, digests)
    return [f"{len(sources)} files copied from {len(entries)} stored jobs into {folder}"]


def upstream(entries: set[Path]) -> list[Path]:
    """``entries`` and every entry whose outputs they read, transitively, sorted."""
    found, todo = set(), list(entries)
    while todo:
        entry = todo.pop()
        if entry in found or not (entry / SUMS).is_file():  # gone: pruned, or discarded
            continue
        found.add(entry)
        inputs = [name for name in read_sums(entry) if name.startswith("../")]
        todo += [entry_of(entry / name) for name in inputs]
    return sorted(found)


def _copy_checked(source: Path, target: Path) -> str:
    """Copy ``source`` to ``target`` (written aside, flushed, renamed into place) while
    hashing it; its SHA-256, which must be the one its entry lists."""
    entry = entry_of(source)
    listed = read_sums(entry).get(Path(os.path.abspath(source)).relative_to(entry).as_posix())
    digest = hashlib.sha256()
    target.parent.mkdir(parents=True, exist_ok=True)
    with atomic_output(target) as tmp, open(source, "rb") as read, open(tmp, "wb") as write:
        while chunk := read.read(CHUNK):
            digest.update(chunk)
            write.write(chunk)
        if digest.hexdigest() != listed:
            discard(entry)
            raise DamagedEntry(
                f"stored result {source} does not match its digest in {entry}/SHA256SUMS: "
                "the entry is discarded; run the workflow again to compute it anew"
            )
    return digest.hexdigest()


def _copy_records(entry: Path, folder: Path) -> None:
    """The log and benchmark file of the job of ``entry``, into the run folder (where
    they can be read: in a group's store, another member's benchmark file has the mode
    that member's umask gave it)."""
    match = ENTRY.match(entry.name)
    name = match["rule"] + (f"/{match['label']}" if match["label"] else "")
    for record, into in (("log", f"logs/{name}.log"), ("benchmark.tsv", f"benchmarks/{name}.tsv")):
        if os.access(entry / record, os.R_OK):
            (folder / into).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(entry / record, folder / into)
