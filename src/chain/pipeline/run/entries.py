"""The result store's entries: one folder per job, its outputs and their digests.

A job whose results runs share writes its outputs into a folder of the store named by
its rule, its wildcards and the key of its recipe (``simulate-elastic_N25-<key>``),
then seals it (:func:`seal`): ``SHA256SUMS`` lists the SHA-256 of each output (as
``sha256sum -c`` reads it, from the folder) and of each input it read from another
entry (``../<entry>/<file>``), and the outputs become read-only. The job's log and
Snakemake's benchmark file sit beside them, unlisted: they are not results.

A stored file is checked against its digest before it is handed on: by the job that
reads it (:func:`verify_inputs`), and by the copy into a run folder. Before any job,
the run looks over every sealed entry (:func:`entry_problem`: a listed file missing,
writable, replaced or changed after the seal) and discards a damaged one, so that
Snakemake computes it again.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
from collections.abc import Iterable
from pathlib import Path

from chain.atomic import write_text_atomic
from chain.pipeline.provenance.checksums import file_digest, files_under

#: An entry's list of digests (the format of ``sha256sum``).
SUMS = "SHA256SUMS"
#: An entry's folder name: rule, wildcards' label, 32 hex digits of its recipe's key.
ENTRY = re.compile(r"^(?P<rule>[A-Za-z_]\w*)(?:-(?P<label>.+))?-(?P<key>[0-9a-f]{32})$")
#: The group a store is shared with (chain.pipeline.run.store_path): its entries
#: are the group's to read.
GROUP_VARIABLE = "HERTZCHAIN_STORE_GROUP"


class DamagedEntry(RuntimeError):
    """A stored file does not match its entry's digest; the message names it."""


def entry_of(path: str | os.PathLike) -> Path | None:
    """The entry folder holding ``path`` (a stored output), or None (not in an entry)."""
    for folder in Path(os.path.abspath(path)).parents:
        if ENTRY.match(folder.name):
            return folder
    return None


def read_sums(entry: Path) -> dict[str, str]:
    """Relative path -> SHA-256 of an entry's ``SHA256SUMS``."""
    listed = {}
    for line in (entry / SUMS).read_text().splitlines():
        digest, _, name = line.partition("  ")
        listed[name] = digest
    return listed


def stored_files(path: str | os.PathLike) -> list[Path]:
    """The files of a stored output: itself, or the files of a folder."""
    path = Path(path)
    return [path / name for name in files_under(path)] if path.is_dir() else [path]


def verify_inputs(paths: Iterable[str]) -> dict[str, str]:
    """Check every input of a job that another job stored against the digest its entry
    lists; returns path -> SHA-256 of what was checked. A mismatch discards the entry
    (the next run computes it again) and raises :class:`DamagedEntry` naming the file.

    Parameters
    ----------
    paths : iterable of str
        The job's input paths (files or folders); those in no entry are skipped.
    """
    checked = {}
    for path in paths:
        entry = entry_of(path)
        if entry is None or not (entry / SUMS).is_file():
            continue
        listed = read_sums(entry)
        files = stored_files(os.path.abspath(path))
        if os.path.isdir(path):  # and those listed in the folder that are gone
            folder = Path(os.path.abspath(path)).relative_to(entry).as_posix()
            files += sorted({entry / n for n in listed if n.startswith(f"{folder}/")} - set(files))
        for file in files:
            name = file.relative_to(entry).as_posix()
            got = file_digest(file) if file.is_file() and not file.is_symlink() else "missing"
            if listed.get(name) != got:
                discard(entry)
                raise DamagedEntry(
                    f"stored result {file} does not match its digest in {entry / SUMS} "
                    f"(SHA-256 {got[:12]}, listed {str(listed.get(name))[:12]}): the entry "
                    "is discarded; run the workflow again to compute it anew"
                )
            checked[str(file)] = got
    return checked


def seal(outputs: Iterable[str], sums: str, inputs: dict[str, str]) -> None:
    """Seal a job's entry: write ``sums`` (the entry's ``SHA256SUMS``) listing each file
    of ``outputs`` and of ``inputs`` (path -> SHA-256, as :func:`verify_inputs` checked
    them), then make the outputs read-only (a group store's: readable by its group).

    Parameters
    ----------
    outputs : iterable of str
        The job's outputs but ``sums`` (files or folders in the entry).
    sums : str
        The entry's ``SHA256SUMS``.
    inputs : dict
        Input file -> SHA-256.
    """
    entry = Path(os.path.abspath(sums)).parent
    files = [file for path in outputs for file in stored_files(os.path.abspath(path))]
    lines = [f"{file_digest(f)}  {f.relative_to(entry).as_posix()}\n" for f in files]
    lines += [f"{d}  {os.path.relpath(os.path.abspath(p), entry)}\n" for p, d in inputs.items()]
    group = bool(os.environ.get(GROUP_VARIABLE))
    for file in files:
        os.chmod(file, 0o440 if group else stat.S_IMODE(os.stat(file).st_mode) & ~0o222)
    if group:
        for folder in {entry, *(entry / p for f in files for p in f.relative_to(entry).parents)}:
            os.chmod(folder, 0o2770)
        if (entry / "log").is_file():  # the job's log, for the others' run folders
            os.chmod(entry / "log", 0o640)
    write_text_atomic("".join(lines), sums)
    os.chmod(sums, 0o440 if group else stat.S_IMODE(os.stat(sums).st_mode) & ~0o222)


def entry_problem(entry: Path) -> str | None:
    """What is wrong with a sealed entry, if anything: a listed file missing, not a
    regular file, writable, or changed after the seal (newer than its SHA256SUMS, and
    its bytes no longer the listed ones: a file touched is Snakemake's newer input, and
    it reruns what reads it). An entry not sealed yet (its job running, or killed) is
    Snakemake's to judge."""
    try:
        sealed = os.lstat(entry / SUMS).st_mtime_ns
        listed = {n: d for n, d in read_sums(entry).items() if not n.startswith("../")}
    except (OSError, UnicodeDecodeError):
        return None if not (entry / SUMS).exists() else f"{SUMS} unreadable"
    for name, digest in listed.items():
        try:
            info = os.lstat(entry / name)
        except OSError:
            return f"{name} missing"
        if not stat.S_ISREG(info.st_mode):
            return f"{name} is not a regular file"
        if info.st_mode & 0o222 or (
            info.st_mtime_ns > sealed and file_digest(entry / name) != digest
        ):
            return f"{name} was changed after it was stored"
    return None


def discard(entry: Path) -> None:
    """Remove an entry (its read-only files too)."""
    shutil.rmtree(entry, ignore_errors=True)
