"""numba's cache of the kernels kept in step with every file they are compiled from.

numba keys a cached kernel on its own file (time stamp and size) and its own function's
bytecode: what the kernel inlines from another file, and the constants it reads from
one, are not part of the key. So a kernel of :mod:`chain.physics.kernels` would be
loaded unchanged after an edit of :mod:`chain.physics.slopes`, whose right-hand side it
inlines. :func:`forget_if_sources_changed` keeps a digest of the sources in each
kernel's cache folder and removes the kernels' cache indexes when it changes, so that
numba compiles them again. The digest covers every source of the physics kernels: an
edit to any of them recompiles them all (seconds), never a stale one.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

#: The files the kernels are compiled from, beside this module.
SOURCES = ("kernels.py", "reference_kernel.py", "slopes.py")


def sources_digest(sources: Iterable[str | os.PathLike]) -> str:
    """SHA-256 (hex) of the ``sources``' bytes, in the order given, each with its name."""
    digest = hashlib.sha256()
    for source in sources:
        path = Path(source)
        digest.update(path.name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def forget_if_sources_changed(module: str, namespace: dict, sources: Iterable | None = None):
    """Remove the cache indexes of the numba kernels that ``module`` defines when
    ``sources`` changed since the digest kept beside them; then keep the new digest.
    Call it at the end of the module, before any of its kernels runs. Returns whether
    indexes were removed (the sources changed, or no digest was kept).

    Parameters
    ----------
    module : str
        The module's name (``__name__``); its last part names the digest's file,
        ``<part>.sources.sha256``, in the kernels' cache folder.
    namespace : dict
        The module's globals: its kernels are the numba dispatchers in it whose Python
        function the module defines. One without a cache, or whose folder cannot be
        written, is left alone (numba then compiles it in every process anyway).
    sources : iterable of paths, optional
        The files they are compiled from; by default :data:`SOURCES` beside this module.
    """
    here = Path(__file__).parent
    files = [here / s for s in SOURCES] if sources is None else list(sources)
    try:
        current = sources_digest(files)
    except OSError:  # sources not readable as files (an archive install): numba's own way
        return False
    kernels = [
        value
        for value in namespace.values()
        if getattr(getattr(value, "py_func", None), "__module__", None) == module
    ]
    folders = {}
    for kernel in kernels:
        folder = getattr(getattr(kernel, "_cache", None), "cache_path", None)
        if folder is not None:  # None: numba's NullCache
            folders.setdefault(folder, []).append(kernel)
    forgot = False
    for folder, cached in folders.items():
        kept = Path(folder) / f"{module.rsplit('.', 1)[-1]}.sources.sha256"
        with contextlib.suppress(OSError):
            if kept.read_text() == current:
                continue
        forgot = True
        for kernel in cached:
            with contextlib.suppress(AttributeError, OSError):
                os.remove(kernel._cache._cache_file._index_path)
        # Not atomic (chain.atomic is above physics): a digest read half-written only
        # makes another process remove the indexes again, i.e. compile once more.
        with contextlib.suppress(OSError):  # a folder not writable: numba compiles anyway
            kept.write_text(current)
    return forgot
