"""The run folder's ``SHA256SUMS``: every file of a run folder, with its SHA-256, in the
format ``sha256sum -c SHA256SUMS`` reads (run from the folder), written by the run's
last job (:mod:`chain.pipeline.run.publish`) from the digests it checked as it copied
the files (a file changed since is then reported by ``sha256sum -c``). Hidden files and
folders (an interrupted copy's temporary file) are never listed.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Mapping
from pathlib import Path

from chain.atomic import write_text_atomic

#: Bytes read at a time.
CHUNK = 1 << 20
#: The checksum file of a run folder.
CHECKSUMS = "SHA256SUMS"


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of a file's bytes, or of a folder's files (names and digests)."""
    path = Path(path)
    if path.is_dir():
        listing = [f"{name}\0{file_digest(path / name)}" for name in files_under(path)]
        return hashlib.sha256("\n".join(listing).encode()).hexdigest()
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while chunk := stream.read(CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def files_under(folder: str | os.PathLike) -> list[str]:
    """Every file below ``folder``, as sorted relative POSIX paths; hidden files left
    out (Snakemake's ``.snakemake_timestamp``, an interrupted writer's temporary)."""
    root = Path(folder)
    return sorted(
        p.relative_to(root).as_posix()
        for p in root.rglob("*")
        if not p.is_dir() and not any(part.startswith(".") for part in p.relative_to(root).parts)
    )


def run_files(folder: str | os.PathLike) -> list[str]:
    """Every file below ``folder`` but the checksums, as sorted relative POSIX paths; no
    path with a hidden part."""
    root = Path(folder)
    found = []
    for base, folders, files in os.walk(root):
        folders[:] = [f for f in folders if not f.startswith(".")]
        found += [
            (Path(base) / name).relative_to(root).as_posix()
            for name in files
            if not name.startswith(".") and not os.path.islink(Path(base) / name)
        ]
    return sorted(name for name in found if name != CHECKSUMS)


def write_checksums(folder: str | os.PathLike, digests: Mapping[str, str] = {}) -> Path:
    """Write ``<folder>/SHA256SUMS``. Returns its path.

    Parameters
    ----------
    folder : path
        A run folder (``results/<run_name>``).
    digests : mapping, optional
        Path (as the run names it: ``results/<run_name>/...``) -> SHA-256 the run
        checked; any other file is hashed now.
    """
    lines = []
    for name in run_files(folder):
        path = os.path.normpath(os.path.join(folder, name))
        lines.append(f"{digests.get(path) or file_digest(path)}  {name}\n")
    write_text_atomic("".join(lines), Path(folder) / CHECKSUMS)
    return Path(folder) / CHECKSUMS


def checksum_problems(folder: str | os.PathLike) -> list[str]:
    """What ``sha256sum -c SHA256SUMS`` would reject in a run folder, in words: no
    checksums (the last run there failed or was interrupted), or a listed file missing
    or changed since the run certified it, or a file the run did not certify.

    Parameters
    ----------
    folder : path
        A run folder (``results/<run_name>``).
    """
    sums = Path(folder) / CHECKSUMS
    if not sums.is_file():
        return [f"{sums}: missing: the last run in this folder did not complete (a failed "
                "or interrupted run leaves none); run the pipeline again"]  # fmt: skip
    listed = dict(reversed(line.split("  ", 1)) for line in sums.read_text().splitlines())
    problems = []
    for name in sorted(set(listed) | set(run_files(folder))):
        path = Path(folder) / name
        if name not in listed:
            problems.append(f"{path}: not certified by {CHECKSUMS} (written after the run)")
        elif not path.is_file():
            problems.append(f"{path}: listed in {CHECKSUMS}, missing")
        elif file_digest(path) != listed[name]:
            problems.append(f"{path}: changed since the run certified it ({CHECKSUMS})")
    return problems
