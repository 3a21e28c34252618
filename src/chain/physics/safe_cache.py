"""numba's cache of the kernels used only from a folder that no other account can write.

numba reads a kernel's cache index (``<module>.<function>-<line>.py311.nbi``) with
``pickle.load`` before it checks anything, and a pickle can run any code. :func:`allowed`
finds the folder numba would use for a module's kernels and checks it before they are
decorated (:func:`chain.trust.problem`: the sources' ``__pycache__`` is trusted as the
sources are, any other folder is checked with its parents); the modules pass the verdict
as ``njit(cache=...)``. Without the cache the kernels are compiled in each process, and
:mod:`chain.physics.kernel_cache` and :mod:`chain.physics.compile_once` write nothing.

A ``__pycache__`` more open than its sources is passed over for the user's own folder
(``~/.cache/numba/...``, made 0700), where numba goes when ``__pycache__`` is read-only.
numba has no cache folder per module; it reads ``numba.config.CACHE_DIR`` (what
``NUMBA_CACHE_DIR`` sets) as each kernel is decorated: that is pointed there for the
rest of the process (other packages' kernels then go there too, each to its own folder).
"""

from __future__ import annotations

import functools
import os
import sys
from pathlib import Path

import numba
from numba.core.caching import _CacheLocator
from numba.misc.appdirs import AppDirs

from chain import trust


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
    folder = _verdict(os.path.dirname(os.path.abspath(module_file)))
    if folder is not None and folder.name != "__pycache__" and not numba.config.CACHE_DIR:
        numba.config.CACHE_DIR = str(folder.parent)  # numba would take __pycache__ first
    return folder is not None


@functools.cache
def _verdict(sources: str) -> Path | None:
    """The folder the kernels of the source folder ``sources`` (absolute path) may be
    cached in, None: in none (said once)."""
    folder, problem = cache_folder(sources)
    if problem:
        fix = "point NUMBA_CACHE_DIR at a folder you make yourself with `mkdir -m 700`"
        fix += ", e.g. /tmp/$USER/numba" + (", or unset it" if numba.config.CACHE_DIR else "")
        print(
            f"hertzchain: numba's cache folder {folder} is not used ({problem}): the "
            f"kernels are compiled in this process instead. Fix: {fix}.",
            file=sys.stderr,
        )
    return None if problem else folder


def cache_folder(sources: str) -> tuple[Path | None, str | None]:
    """The folder for the kernels of a source folder, made if missing (each missing level
    0700, below an existing folder that is safe), and what makes it unsafe: numba's
    choice, the first it can write to of ``$NUMBA_CACHE_DIR/<name>_<sha1 of the source
    folder>``, ``<sources>/__pycache__`` (passed over if more open than ``sources``) and
    ``~/.cache/numba/<name>_<sha1>`` (``$XDG_CACHE_HOME/numba/...``).

    Parameters
    ----------
    sources : str
        Absolute path of the folder of the kernels' source files.

    Returns
    -------
    folder : Path or None
        The folder to use; None when numba can write to none of them.
    problem : str or None
        Why loading from it is unsafe (:func:`chain.trust.problem`); None when it is safe.
    """
    subpath = _CacheLocator.get_suitable_cache_subpath(os.path.join(sources, "_.py"))
    user_wide = AppDirs(appname="numba", appauthor=False).user_cache_dir
    code, in_tree = Path(sources), Path(sources, "__pycache__")
    candidates = [in_tree, Path(user_wide, subpath)]
    if numba.config.CACHE_DIR:
        candidates.insert(0, Path(numba.config.CACHE_DIR, subpath))
    for candidate in candidates:
        folder = Path(os.path.abspath(candidate))
        levels = [folder, *folder.parents]
        existing = next(level for level in levels if os.path.lexists(level))
        if not os.access(existing, os.W_OK | os.X_OK):
            continue  # numba cannot write there either: it tries the next folder
        problem = trust.problem(folder, code)
        if problem is None and existing != folder:
            if not _make_private(levels[: levels.index(existing)]):
                continue
            problem = trust.problem(folder, code)  # another account may have made a level first
        if problem is None or candidate != in_tree:
            return folder, problem
    return None, None


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
