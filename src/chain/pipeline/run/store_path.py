"""The result store's folder, its whole path checked before any job.

The rule is :mod:`chain.trust`'s: a store inside a folder of the code the run executes
(the checkout, the folder of the workflow's Snakefile) is trusted as that code is; any
other (``HERTZCHAIN_STORE``, a group's store) is checked with every folder above it,
each owned by the user or root and writable by no one else (a group's store: by its
members and that group, never by everyone). A missing store is made the user's (0700)
or its group's (2770), and the folders above it writable by the user alone.

Owners and modes are what the file system reports. Some report others than the
accounts' own (NFS with root squash maps root to ``nobody``; SMB shares and FAT disks
give every file one owner and mode): a refusal there names the file system
(:data:`FOREIGN_OWNERS`).
"""

from __future__ import annotations

import grp
import os
import re
from pathlib import Path

from chain import trust
from chain.atomic import ordinary_mode
from chain.pipeline.run.entries import GROUP_VARIABLE

#: Environment variable naming the store's folder.
STORE_VARIABLE = "HERTZCHAIN_STORE"
#: The store's folder relative to the working directory: ``rm -r results`` empties it.
DEFAULT_FOLDER = "results/.store"
#: File systems whose owners and modes need not be the accounts' own (and ``fuse.*``).
FOREIGN_OWNERS = frozenset(
    {"nfs", "nfs4", "cifs", "smb3", "smbfs", "9p", "vfat", "exfat", "msdos", "ntfs", "ntfs3"}
)


class StoreError(RuntimeError):
    """The store cannot be used safely; the message names its folder."""


def open_store(environ, trusted=(), create: bool = True) -> str:
    """The store's folder as the rules name its files: :data:`STORE_VARIABLE` (relative
    to the working directory), else :data:`DEFAULT_FOLDER`; its whole path checked
    (see the module's docstring), and made if missing when ``create``.

    Parameters
    ----------
    environ : mapping
        The process environment.
    trusted : sequence of Path
        Folders of the code the run executes (the checkout, the Snakefile's folder).
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
    path = Path(os.path.abspath(root))
    if not any(trust.trusted(path, Path(code)) for code in trusted):
        found = trust.problem(path, group=group)
        if found:
            fix = (
                f"who could swap the store for a tree of theirs: set {STORE_VARIABLE} to a "
                "folder only you can write, or `chmod g-w,o-w` that folder if it is yours"
            )
            if found.startswith(f"{path} "):  # the store itself
                fix += f"; {GROUP_VARIABLE} shares a store with one group on purpose"
            raise StoreError(f"result store {root}: {found}, {fix}{_foreign_owners(path)}")
    if create and not path.is_dir():
        try:
            _make(path, group)
        except OSError as error:
            where = f"{error.strerror} ({error.filename})"
            fix = f"set {STORE_VARIABLE} to a folder you can write"
            raise StoreError(f"result store {root}: {where}; {fix}") from None
    return root


def _make(path: Path, group: int | None) -> None:
    """Make the store ``path``: the folders above it writable by the user alone, the
    store private (0700), or its group's (2770) whatever the umask."""
    path.parent.mkdir(parents=True, exist_ok=True, mode=ordinary_mode(directory=True) & ~0o022)
    path.mkdir(mode=0o700, exist_ok=True)
    if group is not None and path.stat().st_uid == os.getuid():
        os.chown(path, -1, group)
        os.chmod(path, 0o2770)


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
