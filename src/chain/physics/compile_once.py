"""Each version of a numba kernel compiled by one process at a time.

numba compiles a kernel once per kind of model (its argument types; seconds of CPU
for the step loop) and keeps the result in its cache, but two processes that need
the same version while the cache lacks it both compile it (a fresh clone's two
damped-chain jobs). :func:`shared` takes a lock per version first: the second process
waits for the first, then loads the first's result from numba's cache. The compiled
code is the same either way.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os

#: Byte ranges of a kernel's lock file, one per version (argument types), hashed.
_RANGES = 1 << 30


def shared(kernel):
    """``kernel`` with each version it compiles (or loads from numba's cache) compiled
    under a lock that other processes take too; a decorator above ``numba.njit``.

    numba's dispatcher compiles only when none of its versions fits a call's types, so
    a call costs nothing more (typing the arguments in Python at every call would cost
    ~0.4 ms a launch). Any other callable (a test's stand-in) is returned as it is.
    """
    if not hasattr(kernel, "overloads"):
        return kernel
    compile_version = kernel.compile

    def compile_locked(signature):
        with _version_lock(kernel, signature):
            return compile_version(signature)

    kernel.compile = compile_locked  # what numba's dispatcher calls for a new version
    return kernel


@contextlib.contextmanager
def _version_lock(kernel, signature):
    """An exclusive POSIX lock on one byte of ``<cache folder>/<kernel>.compile.lock``,
    at an offset given by the version's types; nothing when the kernel has no cache
    or its folder cannot be written (then processes may compile the same version, as
    numba does by default). The kernel releases it if the process dies. (POSIX locks
    belong to the process: its own threads do not wait here, but on numba's lock.)"""
    folder = getattr(kernel._cache, "cache_path", None)  # None: numba's NullCache
    name = f"{kernel.py_func.__module__}.{kernel.__name__}.compile.lock"
    try:
        descriptor = os.open(os.path.join(folder, name), os.O_RDWR | os.O_CREAT, 0o644)
    except (TypeError, OSError):
        yield
        return
    digest = hashlib.sha256(str(signature).encode()).digest()
    offset = int.from_bytes(digest[:8], "big") % _RANGES
    try:
        try:
            fcntl.lockf(descriptor, fcntl.LOCK_EX, 1, offset)
        except OSError:  # a file system without POSIX locks (ENOLCK): compile unlocked
            pass
        yield
    finally:
        os.close(descriptor)  # releases the lock
