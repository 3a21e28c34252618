"""The result store: files a job made, kept under a key of everything the job read,
checked byte for byte whenever they are handed on.

An entry is a folder ``<store>/<key[:2]>/<key>/`` holding ``files/<i>`` (the job's
i-th output: a file, or a folder of files) and ``manifest.json`` (each file's SHA-256
and size, recorded as it was stored). Entries appear whole: they are written in
``<store>/tmp/``, flushed to disk, and renamed into place, so a killed run leaves no
partial entry and two runs storing one key at once keep one. Stored files are
read-only; the store is the user's alone (0700) unless it is shared on purpose with
one group (:data:`GROUP_VARIABLE`: 2770, files 0440), never with everyone. Its whole
path is checked as it is opened, and it is held by descriptor from then on
(:mod:`chain.pipeline.run.store_path`). A reader copies each file while hashing it
and renames the copies into place only if every digest is the recorded one: a file
altered, truncated or replaced after it was stored is found, the entry discarded and
the job computed anew (:class:`BadEntry`).
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import weakref
from collections.abc import Iterator
from pathlib import Path

from chain.atomic import ordinary_mode
from chain.pipeline.run.staging import (
    FOLDER_FLAGS,
    remove_at,
    remove_stale_staging,
    staging_name,
)
from chain.pipeline.run.store_files import (
    CREATE,
    BadEntry,
    check_output,
    copy_hashing,
    copy_out,
    file_digest,
    folder_at,
    manifest_and_size,
    manifest_of,
    open_regular,
    stored_digest,
    write_all,
)
from chain.pipeline.run.store_path import (
    GROUP_VARIABLE,
    STORE_VARIABLE,
    StoreError,
    group_id,
    open_store_folder,
)

__all__ = [
    "DEFAULT_FOLDER",
    "GROUP_VARIABLE",
    "STORE_VARIABLE",
    "BadEntry",
    "Store",
    "StoreError",
    "file_digest",
    "remove_stale_staging",
    "stored_digest",
]

#: The store's folder relative to the working directory: ``rm -r results`` empties it.
DEFAULT_FOLDER = Path("results") / ".store"

# What a rename onto an entry's name says when something is there already.
_TAKEN = (errno.EEXIST, errno.ENOTEMPTY, errno.ENOTDIR, errno.EISDIR)
_KEY = re.compile(r"[0-9a-f]{64}")


class Store:
    """A store folder, opened by :meth:`open` and held by descriptor: every access goes
    through it, whatever its path names later.

    Parameters
    ----------
    root : Path
        The store's folder, as the user named it (for messages).
    fd : int
        Its open descriptor (closed with the store: :meth:`close`).
    group : int or None
        The id of the group it is shared with; None: the user's alone.
    """

    def __init__(self, root: Path, fd: int, group: int | None = None):
        self.root, self.group = Path(root), group
        # Read-only; for a group, readable by it whatever the umask, never by others.
        self.file_mode = 0o444 & ordinary_mode() if group is None else 0o440
        self.folder_mode = 0o700 if group is None else 0o2770
        self._fd = fd
        self._closer = weakref.finalize(self, os.close, fd)

    def close(self) -> None:
        """Close the store's descriptor (done too when the store is collected)."""
        self._closer()

    def __enter__(self) -> Store:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    @classmethod
    def open(cls, environ, working_directory: str | os.PathLike = ".", create: bool = True):
        """The store the environment names (:data:`STORE_VARIABLE`, relative to
        ``working_directory``; default :data:`DEFAULT_FOLDER`), its whole path checked
        (:func:`chain.pipeline.run.store_path.open_store_folder`); made if missing when
        ``create``, and then what killed runs of this machine left in its ``tmp``
        removed. Returns the :class:`Store`, or None when it is missing and not
        ``create``.

        Parameters
        ----------
        environ : mapping
            The process environment.
        working_directory : path
            Where a relative store folder starts (Snakemake's working directory).
        create : bool
            Make what is missing. False writes nothing (a dry run).

        Raises
        ------
        StoreError
            A folder of its path is not safe, or it cannot be made; the message names
            the folder and the fix.
        """
        root = Path(working_directory) / (environ.get(STORE_VARIABLE) or DEFAULT_FOLDER)
        group = group_id(environ.get(GROUP_VARIABLE))
        fd = open_store_folder(root, create, 0o700 if group is None else 0o2770, group)
        if fd is None:
            return None
        if create:
            with contextlib.suppress(OSError):
                tmp = os.open("tmp", FOLDER_FLAGS, dir_fd=fd)
                try:
                    remove_stale_staging(tmp)
                finally:
                    os.close(tmp)
        return cls(root, fd, group)

    def entry(self, key: str) -> Path:
        """The path of the entry of ``key`` (a store key: 64 hex digits), for messages;
        it may not exist, and reads go through the store's descriptor."""
        return self.root / key[:2] / key

    def fetch(self, key: str, outputs: list[str]) -> dict | None:
        """Copy ``key``'s stored files to ``outputs`` (paths, in order) and return the
        entry's manifest; None if there is no entry. Each copy is staged beside its
        output, hashed as it is written, flushed to disk, and renamed into place only
        when every file matched its manifest; SIGINT and SIGTERM meanwhile remove the
        staged copies, and what a killed fetch left beside the outputs goes first
        (:func:`remove_stale_staging`).

        Parameters
        ----------
        key : str
            The job's key (64 hex digits).
        outputs : list of str
            The job's output paths, in the order they were stored.

        Raises
        ------
        BadEntry
            The entry is damaged (the message names the file); it has been discarded,
            and no output was written.
        """
        try:
            entry = self._open_entry(key)
            if entry is None:
                return None
            try:
                manifest = manifest_of(entry, len(outputs))
                copy_out(entry, manifest, [Path(out) for out in outputs])
            finally:
                os.close(entry)
        except BadEntry:
            self.discard(key)
            raise
        return manifest

    def verify(self, key: str, count: int) -> dict | None:
        """Check every file of ``key``'s entry against its manifest, copying nothing and
        writing nothing (a dry run); the manifest, or None if there is no entry.

        Parameters
        ----------
        key : str
            The job's key (64 hex digits).
        count : int
            The job's number of outputs.

        Raises
        ------
        BadEntry
            The entry is damaged (the message names the file); it is left in place.
        """
        entry = self._open_entry(key)
        if entry is None:
            return None
        try:
            manifest = manifest_of(entry, count)
            files = folder_at(entry, "files")
            try:
                for i, record in enumerate(manifest["outputs"]):
                    paths = manifest.get("paths") or []
                    label = str(paths[i]) if i < len(paths) else f"files/{i}"
                    check_output(files, str(i), record, label, None)
            finally:
                os.close(files)
        finally:
            os.close(entry)
        return manifest

    def recorded(self, key: str) -> dict | None:
        """``key``'s manifest as recorded (unchecked), or None if absent or unreadable."""
        entry = self._open_entry(key)
        if entry is None:
            return None
        try:
            return manifest_of(entry, None)
        except BadEntry:
            return None
        finally:
            os.close(entry)

    def put(self, key: str, outputs: list[str], about: dict, replace: bool = False) -> dict:
        """Store the files ``outputs`` (paths, in order) under ``key``, with ``about``
        (who stored them, when: ``run``, ``stored``, ``paths``...) in the manifest.
        An existing entry is kept (another run stored the same result) unless
        ``replace``; one whose manifest is damaged is replaced. Every stored file and
        folder is flushed to disk before the entry is renamed into place.

        Parameters
        ----------
        key : str
            The job's key (64 hex digits).
        outputs : list of str
            The job's output paths (files or folders), in order.
        about : dict
            JSON values the manifest records beside the files.
        replace : bool
            Replace an entry already stored (a forced run).

        Returns
        -------
        dict
            The manifest now stored under ``key``: this call's, or the kept entry's.
            ``outputs[i]`` maps each file of output i to [SHA-256, size in bytes]
            ("" for an output that is a file).
        """
        tmp = self._made(self._fd, "tmp")
        name = staging_name()
        try:
            staging = self._made(tmp, name)
            try:
                files = self._made(staging, "files")
                try:
                    records = [self._stage(Path(p), files, str(i)) for i, p in enumerate(outputs)]
                    os.fsync(files)
                finally:
                    os.close(files)
                manifest = {**about, "key": key, "outputs": records}
                text = json.dumps(manifest, indent=1).encode()
                self._write(staging, "manifest.json", lambda out: write_all(out, text))
                os.fsync(staging)
            finally:
                os.close(staging)
            return self._install(tmp, name, key, manifest, replace)
        finally:
            remove_at(tmp, name)  # a failed put's staging (none once installed)
            os.close(tmp)

    def discard(self, key: str) -> None:
        """Remove the entry of ``key`` (64 hex digits), renamed away first: a reader sees
        it whole or not. Nothing happens where the store cannot be written."""
        try:
            prefix = os.open(key[:2], FOLDER_FLAGS, dir_fd=self._fd)
        except OSError:
            return
        try:
            tmp = self._made(self._fd, "tmp")
            try:
                gone = staging_name()
                os.rename(key, gone, src_dir_fd=prefix, dst_dir_fd=tmp)
                remove_at(tmp, gone)
            finally:
                os.close(tmp)
        except OSError:  # gone already, or a read-only store: never handed on anyway
            pass
        finally:
            os.close(prefix)

    def entries(self) -> Iterator[tuple[str, dict | None, int]]:
        """Every entry of the store: its key, its manifest (None if unreadable) and its
        size (bytes of its files and manifest)."""
        with os.scandir(self._fd) as found:
            prefixes = sorted(e.name for e in found if re.fullmatch("[0-9a-f]{2}", e.name))
        for name in prefixes:
            try:
                prefix = os.open(name, FOLDER_FLAGS, dir_fd=self._fd)
            except OSError:
                continue
            try:
                with os.scandir(prefix) as found:
                    keys = sorted(e.name for e in found if _KEY.fullmatch(e.name))
                for key in keys:
                    try:
                        found = manifest_and_size(prefix, key)
                    except OSError:  # removed meanwhile
                        continue
                    yield key, *found
            finally:
                os.close(prefix)

    def _open_entry(self, key: str) -> int | None:
        """The descriptor of ``key``'s entry; None if there is none."""
        if not _KEY.fullmatch(key):
            raise ValueError(f"{key!r} is not a store key (64 hex digits)")
        try:
            prefix = os.open(key[:2], FOLDER_FLAGS, dir_fd=self._fd)
        except OSError:
            return None
        try:
            return os.open(key, FOLDER_FLAGS, dir_fd=prefix)
        except FileNotFoundError:
            return None
        except OSError as error:  # a link or a file in its place
            raise BadEntry(f"{key}: {error.strerror}") from None
        finally:
            os.close(prefix)

    def _made(self, parent: int, name: str) -> int:
        """The descriptor of the store folder ``name`` of ``parent``, made if missing."""
        try:
            os.mkdir(name, self.folder_mode, dir_fd=parent)
        except FileExistsError:
            return os.open(name, FOLDER_FLAGS, dir_fd=parent)
        fd = os.open(name, FOLDER_FLAGS, dir_fd=parent)
        self._own(fd, self.folder_mode)
        return fd

    def _own(self, fd: int, mode: int) -> None:
        """Give a new file or folder the store's group (if any) and ``mode``, whatever
        the umask (group first: a change of group may clear the set-group-id bit)."""
        if self.group is not None and os.fstat(fd).st_gid != self.group:
            os.fchown(fd, -1, self.group)
        os.fchmod(fd, mode)

    def _write(self, folder: int, name: str, write) -> None:
        """Make the file ``name`` in ``folder``, ``write(fd)`` it, make it read-only
        (the store's file mode) and flush it to disk."""
        out = os.open(name, CREATE, 0o600, dir_fd=folder)
        try:
            write(out)
            self._own(out, self.file_mode)
            os.fsync(out)
        finally:
            os.close(out)

    def _stage(self, out: Path, files: int, name: str) -> dict:
        """Copy one output into an entry being written; its files' [sha256, size]."""
        if not out.is_dir():
            return {"": self._store_file(out, files, name)}
        record: dict = {}
        folder = self._made(files, name)
        try:
            self._stage_tree(out, folder, "", record)
        finally:
            os.close(folder)
        return record

    def _stage_tree(self, source: Path, folder: int, prefix: str, record: dict) -> None:
        """Copy the files below ``source`` into ``folder`` (those :func:`files_under`
        lists), recording each under ``prefix`` + its name; flush the folder."""
        with os.scandir(source) as found:
            entries = sorted(found, key=lambda entry: entry.name)
        for entry in entries:
            if entry.is_dir(follow_symlinks=False):
                sub = self._made(folder, entry.name)
                try:
                    self._stage_tree(Path(entry.path), sub, f"{prefix}{entry.name}/", record)
                finally:
                    os.close(sub)
            elif entry.is_file() and not entry.name.startswith("."):
                record[prefix + entry.name] = self._store_file(Path(entry.path), folder, entry.name)
        os.fsync(folder)

    def _store_file(self, source: Path, folder: int, name: str) -> list:
        """Copy the regular file ``source`` to ``name`` in ``folder``: [sha256, size]."""
        got = []
        read = open_regular(None, source)
        try:
            self._write(folder, name, lambda out: got.extend(copy_hashing(read, out)))
        finally:
            os.close(read)
        return got

    def _install(self, tmp: int, name: str, key: str, manifest: dict, replace: bool) -> dict:
        """Rename the staged entry ``name`` into place; the manifest then stored."""
        prefix = self._made(self._fd, key[:2])
        try:
            if replace:
                self.discard(key)
            for _ in range(3):
                try:
                    os.rename(name, key, src_dir_fd=tmp, dst_dir_fd=prefix)
                except OSError as error:
                    if error.errno not in _TAKEN:
                        raise
                else:
                    os.fsync(prefix)
                    return manifest
                try:  # stored meanwhile by another run: one entry is kept
                    kept = manifest_and_size(prefix, key, len(manifest["outputs"]))[0]
                except (BadEntry, OSError):
                    kept = None
                if kept is not None:
                    return kept
                self.discard(key)  # damaged: replaced
        finally:
            os.close(prefix)
        raise OSError(errno.EEXIST, "a damaged entry cannot be replaced", str(self.entry(key)))
