"""Where the store's writers stage what they write, so that a killed one leaves
nothing for long.

A staging file or folder is named ``.hertzchain-<random>-<pid>-<host>``: hidden, so
that no checksum list or stored folder counts it, and naming the process that writes
it, so that a later call on the same machine (:func:`remove_stale_staging`) removes
those whose process is gone (a SIGKILL, a power cut). SIGINT and SIGTERM during a
write raise (:func:`interruptible`), and the writer removes its staging as the
exception passes.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import stat
import threading
from collections.abc import Iterator
from contextlib import contextmanager

#: How every staging name starts.
PREFIX = ".hertzchain-"
#: Open a folder, never through a link.
FOLDER_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC


def staging_name() -> str:
    """A new staging name for this process (see the module's docstring)."""
    return f"{PREFIX}{os.urandom(6).hex()}-{os.getpid()}-{socket.gethostname()}"


def _stale(name: str, host: str) -> bool:
    """Whether ``name`` is staging of a process of the machine ``host`` that is gone."""
    try:
        _, pid, its_host = name[len(PREFIX) :].split("-", 2)
        if its_host != host:
            return False
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return True
    except (ValueError, OSError):  # not a staging name, or another user's live process
        return False
    return False


def remove_at(folder: int, name: str) -> None:
    """Remove the file or folder ``name`` of the open folder ``folder``, if it is there.

    Parameters
    ----------
    folder : int
        A folder's descriptor.
    name : str
        A name in it.
    """
    try:
        info = os.stat(name, dir_fd=folder, follow_symlinks=False)
        if stat.S_ISDIR(info.st_mode):
            shutil.rmtree(name, dir_fd=folder)
        else:
            os.unlink(name, dir_fd=folder)
    except FileNotFoundError:
        pass


def remove_stale_staging(folder: str | os.PathLike | int) -> list[str]:
    """Remove what killed writers of this machine left in ``folder``: staging files and
    folders whose process is gone. Another machine's are left to it (a process id
    says nothing here of a process there). Returns the names removed.

    Parameters
    ----------
    folder : path or int
        A folder (a run folder's, the store's ``tmp``), or its open descriptor.
    """
    try:
        fd = folder if isinstance(folder, int) else os.open(folder, FOLDER_FLAGS)
    except (FileNotFoundError, NotADirectoryError):
        return []
    try:
        with os.scandir(fd) as entries:
            names = [e.name for e in entries if e.name.startswith(PREFIX)]
        host = socket.gethostname()
        stale = [name for name in names if _stale(name, host)]
        for name in stale:
            remove_at(fd, name)
        return stale
    finally:
        if fd is not folder:
            os.close(fd)


def _terminate(signum: int, frame) -> None:
    raise SystemExit(128 + signum)


@contextmanager
def interruptible() -> Iterator[None]:
    """A block that SIGTERM ends by raising ``SystemExit(143)``, as SIGINT raises
    KeyboardInterrupt, so that its ``finally`` and ``except`` clauses remove what it
    staged. Only where Python can set a handler (the main thread) and none is set:
    a handler of the program's own (Snakemake's, a job's) is left to do its work.
    """
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL
    ):
        yield
        return
    signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
