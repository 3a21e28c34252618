"""numba's cache of the kernels used only in a folder that no other account can write.

numba reads a kernel's cache index (``<module>.<function>-<line>.py311.nbi``) with
``pickle.load`` before it checks anything, and a pickle can run any code: whoever can
write the cache folder, or replace it through a folder above it, can run code as the
user who calls the kernels (another account that made ``/tmp/$USER/numba`` first and
left an index in it). :func:`allowed` finds the folder numba would use for a module's
kernels and checks it and every folder above it before the kernels are decorated; the
kernels' modules pass the verdict as ``njit(cache=...)``. Without the cache the kernels
are compiled in each process, and :mod:`chain.physics.kernel_cache` and
:mod:`chain.physics.compile_once` write nothing there either (such a kernel has no
cache folder).
"""

from __future__ import annotations

import functools
import os
import pwd
import stat
import sys
from pathlib import Path

import numba
from numba.core.caching import _CacheLocator
from numba.misc.appdirs import AppDirs


def allowed(module_file: str) -> bool:
    """Whether numba may cache the kernels of a module: the value of their
    ``njit(cache=...)``. When not, one line on stderr names the folder, what is wrong
    with it and what to do (once per process).

    Parameters
    ----------
    module_file : str
        The module's file (its ``__file__``). numba keeps the kernels of all the modules
        of one folder in one cache folder: the verdict is made once per source folder.
    """
    return _verdict(os.path.dirname(os.path.abspath(module_file)))


@functools.cache
def _verdict(sources: str) -> bool:
    """:func:`allowed` for the source folder ``sources`` (absolute path), said once."""
    folder, problem = cache_folder(sources)
    if problem:
        fix = "point NUMBA_CACHE_DIR at a folder you make yourself with `mkdir -m 700`"
        fix += ", e.g. /tmp/$USER/numba" + (", or unset it" if numba.config.CACHE_DIR else "")
        print(
            f"hertzchain: numba's cache folder {folder} is not used ({problem}): the "
            f"kernels are compiled in this process instead. Fix: {fix}.",
            file=sys.stderr,
        )
    return folder is not None and problem is None


def cache_folder(sources: str) -> tuple[Path | None, str | None]:
    """The folder numba would keep the kernels of a source folder in, made if missing
    (each missing level 0700, below an existing folder that is safe), and what makes it
    unsafe.

    numba takes the first folder it can write to of ``$NUMBA_CACHE_DIR/<name>_<sha1 of
    the source folder>``, ``<sources>/__pycache__`` and the user-wide
    ``~/.cache/numba/<name>_<sha1>`` (``$XDG_CACHE_HOME/numba/...``).

    Parameters
    ----------
    sources : str
        Absolute path of the folder of the kernels' source files.

    Returns
    -------
    folder : Path or None
        The folder numba would use; None when it can write to none of them.
    problem : str or None
        Why loading from it is unsafe (:func:`unsafe`); None when it is safe.
    """
    subpath = _CacheLocator.get_suitable_cache_subpath(os.path.join(sources, "_.py"))
    user_wide = AppDirs(appname="numba", appauthor=False).user_cache_dir
    candidates = [os.path.join(sources, "__pycache__"), os.path.join(user_wide, subpath)]
    if numba.config.CACHE_DIR:
        candidates.insert(0, os.path.join(numba.config.CACHE_DIR, subpath))
    for candidate in candidates:
        folder = Path(os.path.abspath(candidate))
        levels = [folder, *folder.parents]
        existing = next(level for level in levels if os.path.lexists(level))
        if not os.access(existing, os.W_OK | os.X_OK):
            continue  # numba cannot write there either: it tries the next folder
        problem = unsafe(folder)
        if problem is None and existing != folder:
            if not _make_private(levels[: levels.index(existing)]):
                continue
            problem = unsafe(folder)  # another account may have made a level first
        return folder, problem
    return None, None


def unsafe(folder: Path) -> str | None:
    """What lets another account write in ``folder`` or replace it, if anything: the
    first of it and the folders above it (as written, and with symbolic links resolved)
    that belongs to a user other than this one and root, or that its group or others
    may write in. A sticky folder above it (``/tmp``, mode 1777) is fine: others may add
    names there, but not rename or remove this user's. E.g. ``/tmp/ann is owned by uid
    1001 (bob)``; None when no other account can.

    Parameters
    ----------
    folder : Path
        The folder, absolute path; of a missing one, the folders above it that exist
        are checked.
    """
    real = Path(os.path.realpath(folder))
    for path in [folder, *folder.parents, real, *real.parents]:
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            continue
        except OSError as error:
            return f"{path} cannot be checked: {error.strerror}"
        if info.st_uid not in (0, os.geteuid()):
            return f"{path} is owned by {_user(info.st_uid)}"
        shared = info.st_mode & 0o022 and not stat.S_ISLNK(info.st_mode)
        if shared and not (info.st_mode & stat.S_ISVTX and path not in (folder, real)):
            mode = stat.filemode(info.st_mode)
            return f"{path} has mode {mode}: its group or others may write in it"
    return None


def _make_private(missing: list[Path]) -> bool:
    """Make the ``missing`` folders (innermost first), outermost first, each 0700;
    whether they all exist now."""
    for level in reversed(missing):
        try:
            os.mkdir(level, 0o700)
        except FileExistsError:
            pass
        except OSError:
            return False
    return True


def _user(uid: int) -> str:
    """``uid 1001 (bob)``, or ``uid 1001`` for a user the system does not name."""
    try:
        return f"uid {uid} ({pwd.getpwuid(uid).pw_name})"
    except KeyError:
        return f"uid {uid}"
