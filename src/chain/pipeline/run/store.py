"""The result store: files a job made, kept under a key of everything the job read,
checked byte for byte whenever they are handed on (issue 52).

An entry is a folder ``<store>/<key[:2]>/<key>/`` holding ``files/<i>`` (the job's
i-th output: a file, or a folder of files) and ``manifest.json`` (each file's SHA-256
and size, recorded as it was stored). Entries appear whole: they are written in
``<store>/tmp/`` and renamed into place, so a killed run leaves no partial entry and two
runs storing one key at once keep one. Stored files are read-only; the store is the
user's alone (0700, files as the umask allows but never writable) unless it is shared
on purpose with one group (:data:`GROUP_VARIABLE`), never with everyone. A reader
copies each file while hashing it and renames the copies into place only if every
digest is the recorded one: a file altered, truncated or replaced after it was stored
is found, the entry discarded and the job computed anew (:class:`BadEntry`).
"""

from __future__ import annotations

import errno
import grp
import hashlib
import json
import os
import shutil
import stat
from pathlib import Path

from chain.atomic import ordinary_mode

#: Environment variable naming the store's folder (default :data:`DEFAULT_FOLDER`).
STORE_VARIABLE = "HERTZCHAIN_STORE"
#: Environment variable naming the one group the store is shared with, if any.
GROUP_VARIABLE = "HERTZCHAIN_STORE_GROUP"
#: The store's folder relative to the working directory: ``rm -r results`` empties it.
DEFAULT_FOLDER = Path("results") / ".store"

_CHUNK = 1 << 20  # bytes read at a time


class StoreError(RuntimeError):
    """The store cannot be used safely; the message names its folder."""


class BadEntry(Exception):
    """A stored entry does not match its manifest; the message says which file."""


def file_digest(path: str | os.PathLike) -> str:
    """SHA-256 (hex) of a file's bytes, or of a folder's files (:func:`stored_digest`)."""
    path = Path(path)
    if path.is_dir():
        return _listing({name: file_digest(path / name) for name in _files_under(path)})
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        while chunk := stream.read(_CHUNK):
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


def _files_under(folder: Path) -> list[str]:
    """Every file below ``folder``, as sorted relative POSIX paths; hidden files left
    out (Snakemake's ``.snakemake_timestamp``, an interrupted writer's temporary)."""
    return sorted(
        p.relative_to(folder).as_posix()
        for p in folder.rglob("*")
        if p.is_file() and not p.name.startswith(".")
    )


class Store:
    """A store folder, made or checked by :meth:`open`.

    Parameters
    ----------
    root : Path
        The store's folder.
    group : int or None
        The id of the group it is shared with; None: the user's alone.
    """

    def __init__(self, root: Path, group: int | None = None):
        self.root, self.group = Path(root), group
        # Read-only; for a group, readable by it whatever the umask, never by others.
        self.file_mode = 0o444 & ordinary_mode() if group is None else 0o440
        self.folder_mode = 0o700 if group is None else 0o2770

    @classmethod
    def open(
        cls, environ, working_directory: str | os.PathLike = ".", create: bool = True
    ) -> Store | None:
        """The store the environment names (:data:`STORE_VARIABLE`, relative to
        ``working_directory``; default :data:`DEFAULT_FOLDER`), made if missing; refused
        (:class:`StoreError`) if another user owns it or others may write it.

        Parameters
        ----------
        environ : mapping
            The process environment.
        working_directory : path
            Where a relative store folder starts (Snakemake's working directory).
        create : bool
            Make the folder if it is missing; else a missing store is None.
        """
        root = Path(working_directory) / (environ.get(STORE_VARIABLE) or DEFAULT_FOLDER)
        group = environ.get(GROUP_VARIABLE) or None
        try:
            gid = None if group is None else grp.getgrnam(group).gr_gid
        except KeyError:
            raise StoreError(f"{GROUP_VARIABLE}={group}: no such group") from None
        store = cls(root, gid)
        if not create and not root.is_dir():
            return None
        try:
            root.mkdir(parents=True, exist_ok=True, mode=store.folder_mode)
        except OSError as error:
            raise StoreError(
                f"result store {root}: {error.strerror}; set {STORE_VARIABLE} to a folder "
                "you can write, or run with --config reuse=False"
            ) from None
        store._check_root()
        return store

    def _check_root(self) -> None:
        """Refuse a store that someone else may have written to: another user's, or
        one writable by others than the user (and the group it is shared with)."""
        info = self.root.stat()
        mode = stat.S_IMODE(info.st_mode)
        where = f"result store {self.root}"
        if info.st_uid != os.getuid():
            raise StoreError(f"{where} belongs to uid {info.st_uid}, not to you")
        if mode & 0o002 or (self.group is None and mode & 0o020):
            raise StoreError(
                f"{where} is writable by others (mode {mode:04o}): empty it "
                f"(`rm -r {self.root}`) or `chmod 700` it if you trust what it holds; "
                f"{GROUP_VARIABLE} shares a store with one group on purpose"
            )
        if self.group is not None and (info.st_gid, mode) != (self.group, self.folder_mode):
            os.chown(self.root, -1, self.group)
            os.chmod(self.root, self.folder_mode)

    def entry(self, key: str) -> Path:
        """The folder of ``key``'s entry (it may not exist)."""
        return self.root / key[:2] / key

    def fetch(self, key: str, outputs: list[str]) -> dict | None:
        """Copy ``key``'s stored files to ``outputs`` (paths, in order) and return the
        entry's manifest; None if there is no entry. Each copy is hashed as it is
        written and renamed into place only when every file matched its manifest.

        Raises
        ------
        BadEntry
            The entry is damaged (the message names the file); it has been discarded,
            and no output was written.
        """
        entry = self.entry(key)
        if not entry.is_dir():
            return None
        copies: list[tuple[Path, Path]] = []
        try:
            manifest = self._manifest(entry, len(outputs))
            for i, (out, files) in enumerate(zip(outputs, manifest["outputs"])):
                copies.append((self._copy_checked(entry / "files" / str(i), files, out), out))
        except BadEntry:
            for copy, _ in copies:
                _remove(copy)
            self.discard(key)
            raise
        for copy, out in copies:
            if Path(out).is_dir():
                shutil.rmtree(out)
            os.replace(copy, out)
        return manifest

    def verify(self, key: str, count: int) -> dict | None:
        """Check ``key``'s entry of ``count`` outputs, every file against its manifest,
        without copying or changing anything; its manifest, or None if there is none.

        Raises
        ------
        BadEntry
            The entry is damaged (the message names the file).
        """
        entry = self.entry(key)
        if not entry.is_dir():
            return None
        manifest = self._manifest(entry, count)
        for i, files in enumerate(manifest["outputs"]):
            stored = entry / "files" / str(i)
            found = set(_files_under(stored)) if stored.is_dir() else {""}
            if found != set(files):
                raise BadEntry(f"{stored.name}: files {sorted(found ^ set(files))} differ")
            for name, (sha256, size) in files.items():
                got = _hash_regular(stored / name if name else stored)
                if got != (sha256, size):
                    raise BadEntry(f"files/{i}{'/' + name if name else ''}: SHA-256 "
                                   f"{got[0][:12]}... ({got[1]} bytes), stored as "
                                   f"{sha256[:12]}... ({size} bytes)")  # fmt: skip
        return manifest

    def recorded(self, key: str) -> dict | None:
        """``key``'s manifest as recorded (unchecked), or None if absent or unreadable."""
        try:
            return json.loads((self.entry(key) / "manifest.json").read_text())
        except (OSError, ValueError):
            return None

    def _manifest(self, entry: Path, count: int) -> dict:
        try:
            manifest = json.loads((entry / "manifest.json").read_text())
            if len(manifest["outputs"]) != count:
                raise ValueError(f"{len(manifest['outputs'])} outputs, the job has {count}")
            return manifest
        except (OSError, ValueError, KeyError, TypeError) as error:
            raise BadEntry(f"manifest.json unreadable ({error})") from None

    def _copy_checked(self, stored: Path, files: dict, out: str) -> Path:
        """A private copy of ``stored`` beside ``out``, each file checked against
        ``files`` (name -> [sha256, size]; "" names a stored file itself)."""
        out = Path(out)
        out.parent.mkdir(parents=True, exist_ok=True)
        copy = out.parent / f".{out.name}.{os.urandom(4).hex()}"
        found = set(_files_under(stored)) if stored.is_dir() else {""}
        if found != set(files):
            raise BadEntry(f"{stored.name}: files {sorted(found ^ set(files))} differ")
        try:
            for name, (sha256, size) in files.items():
                target = copy / name if name else copy
                target.parent.mkdir(parents=True, exist_ok=True)
                got = _copy_hashing(stored / name if name else stored, target)
                if got != (sha256, size):
                    raise BadEntry(
                        f"{out.name}{'/' + name if name else ''}: SHA-256 {got[0][:12]}... "
                        f"({got[1]} bytes), stored as {sha256[:12]}... ({size} bytes)"
                    )
        except BaseException:
            _remove(copy)
            raise
        return copy

    def put(self, key: str, outputs: list[str], about: dict, replace: bool = False) -> dict:
        """Store the files ``outputs`` (paths, in order) under ``key``, with ``about``
        (who stored them) in the manifest. An existing entry is kept (another run
        stored the same result) unless ``replace``. Returns the manifest of the entry
        that stands: each output's files with their SHA-256 and size.
        """
        tmp = self.root / "tmp"
        tmp.mkdir(exist_ok=True, mode=self.folder_mode)
        staging = tmp / f"{key}.{os.urandom(4).hex()}"
        try:
            os.mkdir(staging, self.folder_mode)
            os.mkdir(staging / "files", self.folder_mode)
            records = [
                self._stage(Path(out), staging / "files" / str(i)) for i, out in enumerate(outputs)
            ]
            manifest = {**about, "key": key, "outputs": records}
            (staging / "manifest.json").write_text(json.dumps(manifest, indent=1))
            os.chmod(staging / "manifest.json", self.file_mode)
            final = self.entry(key)
            final.parent.mkdir(exist_ok=True, mode=self.folder_mode)
            if replace and final.exists():
                self.discard(key)
            os.rename(staging, final)
            return manifest
        except OSError as error:
            if error.errno in (errno.EEXIST, errno.ENOTEMPTY) and self.entry(key).is_dir():
                return {**manifest, **(self.recorded(key) or {})}  # stored meanwhile
            raise
        finally:
            _remove(staging)

    def _stage(self, out: Path, stored: Path) -> dict:
        """Copy one output into an entry being written; its files' [sha256, size]."""
        names = _files_under(out) if out.is_dir() else [""]
        files = {}
        for name in names:
            target = stored / name if name else stored
            for folder in [Path("."), *reversed(Path(name).parents[:-1])] if name else []:
                (stored / folder).mkdir(exist_ok=True, mode=self.folder_mode)
            files[name] = list(_copy_hashing(out / name if name else out, target))
            os.chmod(target, self.file_mode)
        return files

    def discard(self, key: str) -> None:
        """Remove ``key``'s entry (renamed away first: a reader sees it whole or not)."""
        entry = self.entry(key)
        gone = self.root / "tmp" / f"discarded.{key}.{os.urandom(4).hex()}"
        try:
            gone.parent.mkdir(exist_ok=True, mode=self.folder_mode)
            os.rename(entry, gone)
        except OSError:  # gone already, or a read-only store: never handed on anyway
            return
        _remove(gone)


def _copy_hashing(source: Path, target: Path) -> tuple[str, int]:
    """Copy a regular file (never a link), returning the copy's (SHA-256, size)."""
    digest, size = hashlib.sha256(), 0
    try:
        fd = os.open(source, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError as error:  # gone, or a link put in its place
        raise BadEntry(f"{source.name}: {error.strerror}") from None
    with open(fd, "rb") as stream, open(target, "xb") as copy:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise BadEntry(f"{source.name} is not a regular file")
        while chunk := stream.read(_CHUNK):
            digest.update(chunk)
            size += len(chunk)
            copy.write(chunk)
    return digest.hexdigest(), size


def _hash_regular(path: Path) -> tuple[str, int]:
    """(SHA-256, size) of a regular file, never through a link."""
    digest, size = hashlib.sha256(), 0
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError as error:
        raise BadEntry(f"{path.name}: {error.strerror}") from None
    with open(fd, "rb") as stream:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise BadEntry(f"{path.name} is not a regular file")
        while chunk := stream.read(_CHUNK):
            digest.update(chunk)
            size += len(chunk)
    return digest.hexdigest(), size


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)
