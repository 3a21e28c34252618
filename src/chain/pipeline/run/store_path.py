"""The store's folder, opened once its whole path is checked, and held by descriptor.

Every folder from ``/`` down to the store must be writable by no one but the user and
root (sticky folders such as /tmp aside: there no one renames another's files), and
owned by one of them: anyone else who may write one of them could swap the store for
a tree of theirs. The store itself is the user's (0700). The path is walked from ``/``
one folder at a time, never through a link, each folder checked on the descriptor
that will be used: the store is then held by its descriptor, and every later access
goes through it, so that a swap of its path after the check hands nothing on.

A store shared with a group (:data:`GROUP_VARIABLE`) may be owned by any member,
and it and the folders above it may be writable by that group, never by everyone: a
member can write entries.

Owners and modes are what the file system reports. Some report others than the
accounts' own (NFS with root squash maps root to ``nobody``; SMB shares and FAT disks
give every file one owner and mode): a refusal there names the file system
(:data:`FOREIGN_OWNERS`).
"""

from __future__ import annotations

import grp
import os
import pwd
import re
import stat
from pathlib import Path

from chain.atomic import ordinary_mode
from chain.pipeline.run.entries import GROUP_VARIABLE

#: Environment variable naming the store's folder.
STORE_VARIABLE = "HERTZCHAIN_STORE"
#: The store's folder relative to the working directory: ``rm -r results`` empties it.
DEFAULT_FOLDER = "results/.store"
#: A folder, opened without following a link.
FOLDER_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC
#: File systems whose owners and modes need not be the accounts' own (and ``fuse.*``).
FOREIGN_OWNERS = frozenset(
    {"nfs", "nfs4", "cifs", "smb3", "smbfs", "9p", "vfat", "exfat", "msdos", "ntfs", "ntfs3"}
)


class StoreError(RuntimeError):
    """The store cannot be used safely; the message names its folder."""


def open_store(environ, trusted=(), create: bool = True) -> str:
    """The store's folder as the rules name its files: :data:`STORE_VARIABLE` (relative
    to the working directory), else :data:`DEFAULT_FOLDER`; its whole path checked
    (:func:`open_store_folder`), and made if missing when ``create``.

    Parameters
    ----------
    environ : mapping
        The process environment.
    trusted : sequence of Path
        Folders that hold the code the run executes (the checkout, the working folder).
    create : bool
        Make what is missing. False writes nothing (a dry run).

    Raises
    ------
    StoreError
        A folder of its path is not safe, or it cannot be made; the message names the
        folder and the fix.
    """
    root = environ.get(STORE_VARIABLE) or DEFAULT_FOLDER
    if "{" in root or "}" in root:
        raise StoreError(f"{STORE_VARIABLE}={root}: a folder name with braces cannot be used")
    group = group_id(environ.get(GROUP_VARIABLE))
    fd = open_store_folder(Path(root), create, 0o700 if group is None else 0o2770, group)
    if fd is not None:
        os.close(fd)
    return root


def group_id(name: str | None) -> int | None:
    """The id of the group ``name`` (None: no group); refused (:class:`StoreError`)
    if there is no such group or this process is not in it.

    Parameters
    ----------
    name : str or None
        :data:`GROUP_VARIABLE`'s value.
    """
    if not name:
        return None
    try:
        gid = grp.getgrnam(name).gr_gid
    except KeyError:
        raise StoreError(f"{GROUP_VARIABLE}={name}: no such group") from None
    if os.getuid() != 0 and gid != os.getegid() and gid not in os.getgroups():
        raise StoreError(f"{GROUP_VARIABLE}={name}: you are not a member of group {name}")
    return gid


def open_store_folder(root: Path, create: bool, mode: int, group: int | None) -> int | None:
    """The descriptor of the store folder ``root``, each folder from ``/`` to it
    checked (see the module's docstring); None if it is missing and not ``create``.

    Parameters
    ----------
    root : Path
        The store's folder (links in its path are resolved first).
    create : bool
        Make missing folders: the store with ``mode``, those above it writable by the
        user alone. False: write nothing.
    mode : int
        Permission bits of the store's folder (0700, or 2770 for a group).
    group : int or None
        The group the store is shared with.

    Raises
    ------
    StoreError
        A folder is not safe (the message names it and the fix), or cannot be made.
    """
    real = Path(os.path.realpath(root))
    fd, here = None, real
    try:
        for depth in range(1, len(real.parts) + 1):
            here, last = Path(*real.parts[:depth]), depth == len(real.parts)
            # The store is made private; _share then gives a group's store its group.
            made = mode & 0o700 if last else ordinary_mode(directory=True) & ~0o022
            child = _open_or_make(fd, here, create, made)
            if fd is not None:
                os.close(fd)
            fd = child
            if fd is None:
                return None
            if last and create:
                _share(fd, mode, group)
            problem = _problem(os.fstat(fd), here, last, group)
            if problem:
                raise StoreError(f"result store {root}: {problem}{_foreign_owners(here)}")
        return fd
    except BaseException as error:
        if fd is not None:
            os.close(fd)
        if isinstance(error, OSError):
            raise StoreError(
                f"result store {root}: {error.strerror} ({here}); set {STORE_VARIABLE} to a "
                "folder you can write"
            ) from None
        raise


def _open_or_make(parent: int | None, here: Path, create: bool, mode: int) -> int | None:
    """Open the folder ``here`` (``parent``'s, never through a link), made with ``mode``
    if missing and ``create``; None if missing and not."""
    try:
        return os.open(here.name or "/", FOLDER_FLAGS, dir_fd=parent)
    except FileNotFoundError:
        if not create:
            return None
    try:
        os.mkdir(here.name, 0o700, dir_fd=parent)  # private until its mode is set
    except FileExistsError:  # made meanwhile by another run: checked as found
        return os.open(here.name, FOLDER_FLAGS, dir_fd=parent)
    fd = os.open(here.name, FOLDER_FLAGS, dir_fd=parent)
    os.fchmod(fd, mode)  # whatever the umask
    return fd


def _share(fd: int, mode: int, group: int | None) -> None:
    """A group store's folder of the user's given its group and ``mode`` (2770), as
    another member's runs need it whatever the umask it was made under; never one
    that others may have written (everyone, or another group): that one is refused."""
    info = os.fstat(fd)
    others = info.st_mode & 0o002 or (info.st_mode & 0o020 and info.st_gid != group)
    if group is None or info.st_uid != os.getuid() or others:
        return
    if info.st_gid != group:
        os.fchown(fd, -1, group)
    if stat.S_IMODE(os.fstat(fd).st_mode) != mode:
        os.fchmod(fd, mode)


def _problem(info: os.stat_result, here: Path, last: bool, group: int | None) -> str | None:
    """What makes the folder ``here`` unsafe for the store, if anything."""
    mode, me = stat.S_IMODE(info.st_mode), os.getuid()
    if info.st_uid not in (me, 0) and not (group is not None and _member(info.st_uid, group)):
        return f"{here} belongs to uid {info.st_uid}, not to you" + (
            "" if last else f", who could swap the store; set {STORE_VARIABLE} elsewhere"
        )
    sticky = not last and mode & stat.S_ISVTX
    ours = group is not None and info.st_gid == group
    if not sticky and (mode & 0o002 or (mode & 0o020 and not ours)):
        if not last:
            return (
                f"{here} is writable by others (mode {mode:04o}), who could swap the store "
                f"for a tree of theirs: `chmod g-w,o-w {here}`, or set {STORE_VARIABLE} "
                "to a folder only you can write"
            )
        return (
            f"{here} is writable by others (mode {mode:04o}): empty it (`rm -r {here}`) "
            f"or `chmod 700 {here}` if you trust what it holds; {GROUP_VARIABLE} "
            "shares a store with one group on purpose"
        )
    if last and group is not None and not ours:
        name = grp.getgrgid(group).gr_name
        return f"{here} is not group {name}'s: its owner can `chgrp {name}` and `chmod 2770` it"
    return None


def _member(uid: int, gid: int) -> bool:
    """Whether the account ``uid`` is a member of the group ``gid``."""
    try:
        user = pwd.getpwuid(uid)
        return user.pw_gid == gid or user.pw_name in grp.getgrgid(gid).gr_mem
    except KeyError:
        return False


def file_system(path: str | os.PathLike, mountinfo: str = "/proc/self/mountinfo"):
    """The type and mount point of the file system holding ``path`` (a resolved
    path), as Linux lists them; None where it does not.

    Parameters
    ----------
    path : path
        An absolute path without links.
    mountinfo : str
        The mount table (``/proc/self/mountinfo``'s format).
    """
    try:
        lines = Path(mountinfo).read_text().splitlines()
    except OSError:
        return None
    path, found = str(path), None
    for fields in (line.split() for line in lines):
        if "-" not in fields:
            continue
        point = re.sub(r"\\([0-7]{3})", lambda m: chr(int(m.group(1), 8)), fields[4])
        inside = path == point or path.startswith(point.rstrip("/") + "/")
        if inside and (found is None or len(point) >= len(found[1])):  # later mounts hide
            found = (fields[fields.index("-") + 1], point)
    return found


def _foreign_owners(here: Path) -> str:
    """A word on the file system of ``here`` when its owners and modes may not be the
    accounts' own: the check cannot be trusted there."""
    found = file_system(here)
    if found is None or not (found[0] in FOREIGN_OWNERS or found[0].startswith("fuse")):
        return ""
    return (
        f" ({here} is on a {found[0]} file system ({found[1]}), whose owners and modes "
        "need not be the accounts' own (root squash, one owner for a whole share): "
        f"this check cannot be made there; set {STORE_VARIABLE} to a folder on a local disk)"
    )
