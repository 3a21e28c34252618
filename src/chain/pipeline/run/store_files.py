"""The files of the result store, read by descriptor: a stored output's digest, an
entry's manifest, and each stored file checked (and copied out) against it, never
through a link (:mod:`chain.pipeline.run.store` holds the store itself)."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import shutil
import stat
from collections.abc import Iterator
from pathlib import Path

from chain.atomic import sync
from chain.pipeline.run.staging import (
    FOLDER_FLAGS,
    interruptible,
    remove_stale_staging,
    staging_name,
)

CHUNK = 1 << 20  # bytes read at a time
# A regular file, never through a link; a FIFO put in its place does not block.
READ = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC
CREATE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC


class BadEntry(Exception):
    """A stored entry does not match its manifest; the message says which file."""


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of a file's bytes, or of a folder's files (:func:`stored_digest`)."""
    path = Path(path)
    if path.is_dir():
        return _listing({name: file_digest(path / name) for name in files_under(path)})
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while chunk := stream.read(CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def stored_digest(files: dict) -> str:
    """The :func:`file_digest` of a stored output, from its manifest record (name ->
    [sha256, size]; the name "" for a file)."""
    if list(files) == [""]:
        return files[""][0]
    return _listing({name: sha256 for name, (sha256, _) in files.items()})


def _listing(digests: dict) -> str:
    listing = [f"{name}\0{digests[name]}" for name in sorted(digests)]
    return hashlib.sha256("\n".join(listing).encode()).hexdigest()


def files_under(folder: Path) -> list[str]:
    """Every file below ``folder``, as sorted relative POSIX paths; hidden files left
    out (Snakemake's ``.snakemake_timestamp``, an interrupted writer's temporary)."""
    return sorted(
        p.relative_to(folder).as_posix()
        for p in folder.rglob("*")
        if p.is_file() and not p.name.startswith(".")
    )


def manifest_of(entry: int, count: int | None) -> dict:
    """The manifest of the open entry ``entry``, with ``count`` outputs (any: None)."""
    try:
        fd = open_regular(entry, "manifest.json")
        with open(fd, "rb") as stream:
            manifest = json.loads(stream.read())
        outputs = manifest["outputs"]
        if count is not None and len(outputs) != count:
            raise ValueError(f"{len(outputs)} outputs, the job has {count}")
        if not all(
            isinstance(files, dict) and all(len(v) == 2 for v in files.values())
            for files in outputs
        ):
            raise ValueError("an output's record is not {file: [sha256, size]}")
        return manifest
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise BadEntry(f"manifest.json unreadable ({error})") from None


def manifest_and_size(prefix: int, key: str, count: int | None = None):
    """(manifest or None if unreadable, size in bytes) of the entry ``key`` of the open
    folder ``prefix``."""
    entry = os.open(key, FOLDER_FLAGS, dir_fd=prefix)
    try:
        try:
            manifest = manifest_of(entry, count)
        except BadEntry:
            manifest = None
        size = 0
        for _, _, names, folder in os.fwalk(".", dir_fd=entry):
            for name in names:
                info = os.stat(name, dir_fd=folder, follow_symlinks=False)
                size += info.st_size if stat.S_ISREG(info.st_mode) else 0
        return manifest, size
    finally:
        os.close(entry)


def folder_at(parent: int, name: str) -> int:
    """The descriptor of a stored folder (never through a link), or :class:`BadEntry`."""
    try:
        return os.open(name, FOLDER_FLAGS, dir_fd=parent)
    except OSError as error:
        raise BadEntry(f"{name}: {error.strerror}") from None


def open_regular(parent: int | None, name: str | Path) -> int:
    """A descriptor for reading the regular file ``name`` (of ``parent``), never
    through a link: OSError if it is gone, a link, or not a regular file."""
    fd = os.open(name, READ, dir_fd=parent)
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(errno.EINVAL, "not a regular file", os.fspath(name))
    return fd


def walk(folder: int, prefix: str = "") -> Iterator[tuple[str, int, str]]:
    """(path below the stored folder, its folder's descriptor, name) of each file below
    the open ``folder``, sorted, never through a link (a link is listed as a file);
    hidden files left out, as :func:`files_under` does."""
    with os.scandir(folder) as found:
        entries = sorted((e.name, e.is_dir(follow_symlinks=False)) for e in found)
    for name, is_dir in entries:
        if is_dir:
            sub = folder_at(folder, name)
            try:
                yield from walk(sub, f"{prefix}{name}/")
            finally:
                os.close(sub)
        elif not name.startswith("."):
            yield prefix + name, folder, name


def check_output(files: int, name: str, record: dict, label: str, copy: Path | None) -> None:
    """Check the stored output ``files/<name>`` against its ``record`` (file name ->
    [sha256, size]; "" names a stored file itself) file by file, copying it to ``copy``
    meanwhile if given (each file flushed). Raises :class:`BadEntry` naming the file."""
    try:
        is_dir = stat.S_ISDIR(os.stat(name, dir_fd=files, follow_symlinks=False).st_mode)
    except OSError as error:
        raise BadEntry(f"{label}: {error.strerror}") from None
    folder = folder_at(files, name) if is_dir else None
    try:
        if copy is not None and is_dir:
            copy.mkdir()
        seen = set()
        for path, parent, leaf in walk(folder) if is_dir else [("", files, name)]:
            shown = f"{label}/{path}" if path else label
            if path not in record:
                raise BadEntry(f"{shown}: a file the manifest does not list")
            got = check_file(parent, leaf, None if copy is None else copy / path, shown)
            sha256, size = record[path]
            if got != (sha256, size):
                raise BadEntry(
                    f"{shown}: SHA-256 {got[0][:12]}... ({got[1]} bytes), stored as "
                    f"{str(sha256)[:12]}... ({size} bytes)"
                )
            seen.add(path)
        if set(record) - seen:
            raise BadEntry(f"{label}: {sorted(set(record) - seen)} missing")
    finally:
        if folder is not None:
            os.close(folder)


def check_file(parent: int, name: str, copy: Path | None, shown: str) -> tuple[str, int]:
    """(SHA-256, size) of the stored file ``name`` of ``parent``, copied to ``copy``
    (made, flushed) if given."""
    try:
        read = open_regular(parent, name)
    except OSError as error:  # gone, or a link put in its place
        raise BadEntry(f"{shown}: {error.strerror}") from None
    try:
        if copy is None:
            return copy_hashing(read, None)
        copy.parent.mkdir(parents=True, exist_ok=True)
        out = os.open(copy, CREATE, 0o666)  # a copy of the user's, as the umask allows
        try:
            got = copy_hashing(read, out)
            os.fsync(out)
        finally:
            os.close(out)
        return got
    finally:
        os.close(read)


def copy_hashing(source: int, target: int | None) -> tuple[str, int]:
    """Read the open file ``source`` to its end, writing it to ``target`` if given;
    the bytes' (SHA-256, size)."""
    digest, size = hashlib.sha256(), 0
    while chunk := os.read(source, CHUNK):
        digest.update(chunk)
        size += len(chunk)
        if target is not None:
            write_all(target, chunk)
    return digest.hexdigest(), size


def write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def copy_out(entry: int, manifest: dict, outputs: list[Path]) -> None:
    """Copy the open entry's outputs to ``outputs``: staged beside each (what a killed
    fetch left there removed first), checked, then renamed into place."""
    for folder in {out.parent for out in outputs}:
        folder.mkdir(parents=True, exist_ok=True)
        remove_stale_staging(folder)
    copies: list[Path] = []
    with interruptible():
        try:
            files = folder_at(entry, "files")
            try:
                for i, (out, record) in enumerate(zip(outputs, manifest["outputs"])):
                    copies.append(out.parent / staging_name())
                    check_output(files, str(i), record, out.name, copies[-1])
            finally:
                os.close(files)
            for copy, out in zip(copies, outputs):
                into_place(copy, out)
        except BaseException:
            for copy in copies:
                _remove(copy)
            raise


def into_place(copy: Path, out: Path) -> None:
    """Rename the checked ``copy`` to ``out``, flushing what it holds first. A file
    replaces a file at once; a folder in the way is renamed aside and deleted after."""
    if copy.is_dir():
        for folder, _, _ in os.walk(copy, topdown=False):
            sync(folder, directory=True)
    if (out.is_dir() and not out.is_symlink()) or (copy.is_dir() and os.path.lexists(out)):
        old = out.parent / staging_name()
        os.rename(out, old)
        os.rename(copy, out)
        _remove(old)
    else:
        os.replace(copy, out)
    sync(out.parent, directory=True)


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)
