"""The result store's folder, its whole path checked before any job.

The rule is :mod:`chain.trust`'s: a store inside a folder of the code the run executes
(the checkout, the folder of the workflow's Snakefile) is trusted as that code is; any
other (``HERTZCHAIN_STORE``, a group's store) is checked with every folder above it,
each owned by the user or root and writable by no one else (a group's store: by its
members and that group, never by everyone). A missing store is made the user's (0700)
or its group's (2770), and the folders above it writable by the user alone.

Owners and modes are what the file system reports: a refusal on one whose owners are
not the accounts' own names it (:func:`chain.trust.foreign_owners`).
"""

from __future__ import annotations

import grp
import os
from pathlib import Path

from chain import trust
from chain.atomic import ordinary_mode
from chain.pipeline.run.entries import GROUP_VARIABLE

#: Environment variable naming the store's folder.
STORE_VARIABLE = "HERTZCHAIN_STORE"
#: The store's folder relative to the working directory: ``rm -r results`` empties it.
DEFAULT_FOLDER = "results/.store"


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
            note = trust.foreign_owners(path)
            note = f" ({note}; set {STORE_VARIABLE} to a folder on a local disk)" if note else ""
            raise StoreError(f"result store {root}: {found}, {fix}{note}")
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
