"""Who may write a folder: the one rule for the result store and numba's cache.

Whoever may write a folder that a pickle or code is read from, or swap it through a
folder above it, can run code as the user. A folder inside a tree of the code the
process runs (the checkout, a package's folder), no more open than the tree's root, is
trusted as that code is: whoever may write it can change the code anyway. Any other
folder is checked with every folder above it.
"""

from __future__ import annotations

import grp
import os
import pwd
import re
import stat
from pathlib import Path


def problem(folder: Path, code_root: Path | None = None, group: int | None = None) -> str | None:
    """What lets another account write in ``folder`` or swap it, e.g. ``/tmp/ann is
    owned by uid 1001 (bob)``; None if nothing: it is :func:`trusted`, or it and every
    folder above it, as written and with links resolved, pass :func:`level_problem`.

    Parameters
    ----------
    folder : Path
        Absolute path; of a missing one, the folders above it that exist are checked.
    code_root : Path, optional
        A folder of the code the process runs (its checkout, its package's folder).
    group : int, optional
        The id of a group that may write the folders on purpose (a group's store).
    """
    if code_root is not None and trusted(folder, code_root):
        return None
    real = Path(os.path.realpath(folder))
    for path in [folder, *folder.parents, real, *real.parents]:
        try:
            found = level_problem(os.lstat(path), path, path in (folder, real), group)
        except FileNotFoundError:
            continue
        except OSError as error:
            return f"{path} cannot be checked: {error.strerror}"
        if found:
            return found
    return None


def level_problem(info: os.stat_result, path: Path, last: bool, group: int | None = None):
    """What lets another account write in the folder ``path``, if anything: an owner not
    the user, root or a member of ``group``; a mode that lets others, or a group not
    ``group``, write in it, unless it is a link, or sticky (as /tmp: others may add
    names, not rename the user's) and above the ``last`` folder, the one checked.

    Parameters
    ----------
    info : os.stat_result
        ``path``'s ``os.lstat`` or ``os.fstat``.
    path : Path
        The folder, named in the message.
    last : bool
        Whether it is the folder checked rather than one above it.
    group : int, optional
        The id of a group that may write it on purpose (a group's result store).
    """
    mode, owner = info.st_mode, info.st_uid
    if owner not in (0, os.geteuid()) and not (group is not None and _member(owner, group)):
        try:
            return f"{path} is owned by uid {owner} ({pwd.getpwuid(owner).pw_name})"
        except KeyError:
            return f"{path} is owned by uid {owner}"
    if stat.S_ISLNK(mode) or (mode & stat.S_ISVTX and not last):
        return None
    if mode & 0o002 or (mode & 0o020 and info.st_gid != group):
        return f"{path} has mode {stat.filemode(mode)}: its group or others may write in it"
    return None


def trusted(folder: Path, code_root: Path) -> bool:
    """Whether ``folder`` is trusted as the code in ``code_root`` is: it lies inside it
    (as written and with links resolved), and no folder from there down to it is more
    open than ``code_root`` (a sticky one trusts nothing). Its parents are not checked.

    Parameters
    ----------
    folder : Path
        The folder; of a missing one, what exists of its path is checked.
    code_root : Path
        A folder of the code the process runs.
    """
    try:
        root = os.stat(code_root)
        group = root.st_gid if root.st_mode & 0o020 else None
        for resolve in (os.path.abspath, os.path.realpath):
            top, path = Path(resolve(code_root)), Path(resolve(folder))
            if top != path and top not in path.parents:
                return False
            for level in (p for p in [path, *path.parents] if top in p.parents):
                if root.st_mode & 0o002 or not os.path.lexists(level):
                    continue  # everyone may write the root; a missing level has no one
                if level_problem(os.lstat(level), level, True, group):
                    return False
    except OSError:
        return False
    return not root.st_mode & stat.S_ISVTX


def open_code_line(code_root: Path) -> str | None:
    """The console line when accounts other than the user may write ``code_root``:
    everyone, or its group with another account in it (a member, or one whose primary
    group it is; a user private group has none); else None.

    Parameters
    ----------
    code_root : Path
        The checkout of the code the process runs.
    """
    info, me = os.stat(code_root), os.geteuid()
    shared = info.st_mode & 0o020 and any(
        _member(user.pw_uid, info.st_gid) for user in pwd.getpwall() if user.pw_uid != me
    )
    if not (info.st_mode & 0o002 or shared):
        return None
    return (
        f"hertzchain: {code_root} has mode {stat.filemode(info.st_mode)}: accounts other "
        "than you can change the code this run executes (the run goes on). Fix: "
        f"`chmod -R g-w,o-w {code_root}`"
    )


def _member(uid: int, gid: int) -> bool:
    """Whether the account ``uid`` is in the group ``gid`` (or it is its primary group)."""
    try:
        user = pwd.getpwuid(uid)
        return user.pw_gid == gid or user.pw_name in grp.getgrgid(gid).gr_mem
    except KeyError:
        return False


#: File systems whose owners and modes need not be the accounts' own (and ``fuse.*``).
FOREIGN_OWNERS = frozenset(
    {"nfs", "nfs4", "cifs", "smb3", "smbfs", "9p", "vfat", "exfat", "msdos", "ntfs", "ntfs3"}
)


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


def foreign_owners(here: Path) -> str:
    """A word on the file system of ``here`` when its owners and modes need not be the
    accounts' own (NFS with root squash maps root to ``nobody``; SMB shares and FAT
    disks give every file one owner and mode), so that no check of who may write can
    be made there; "" elsewhere.

    Parameters
    ----------
    here : Path
        An absolute path.
    """
    found = file_system(here)
    if found is None or not (found[0] in FOREIGN_OWNERS or found[0].startswith("fuse")):
        return ""
    return (
        f"{here} is on a {found[0]} file system ({found[1]}), whose owners and modes need "
        "not be the accounts' own (root squash, one owner for a whole share): this check "
        "cannot be made there"
    )
