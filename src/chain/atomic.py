"""Atomic file writes: write to a temporary name beside the target, then rename.

An interrupted job (Ctrl-C, a killed Snakemake job, a full disk) therefore never leaves
a half-written file under the final name; ``os.replace`` is atomic on POSIX file
systems. The bytes are flushed to disk (:func:`sync`) before the rename and the rename
after it, so a power cut leaves the old file or the whole new one, never an empty one
under the final name. Every file the library writes goes through :func:`atomic_output`.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd


def ordinary_mode(directory: bool = False) -> int:
    """Permission bits a plain ``open``/``mkdir`` would give under the current umask.

    ``tempfile`` creates private 0600/0700 entries, wrong for shared results.

    Parameters
    ----------
    directory : bool
        Bits for a folder (0777 less the umask) instead of a file (0666 less the umask).
    """
    return (0o777 if directory else 0o666) & ~_umask()


def sync(path: str | os.PathLike, directory: bool = False) -> None:
    """Flush a file's bytes, or a folder's list of names, to disk (``fsync``).

    Parameters
    ----------
    path : path
        A file, or a folder.
    directory : bool
        ``path`` is a folder (its renames and new names are flushed).
    """
    fd = os.open(path, os.O_RDONLY | (os.O_DIRECTORY if directory else 0) | os.O_CLOEXEC)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _umask() -> int:
    # /proc says it without changing it (os.umask does, for every thread meanwhile).
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except OSError:
        pass
    umask = os.umask(0o022)
    os.umask(umask)
    return umask


@contextmanager
def temporary_beside(path: Path, directory: bool = False) -> Iterator[Path]:
    """A new private file (or folder) beside ``path``, named ``.<name>.<random>``,
    removed if the block raises or is interrupted. The name is chosen before the file is
    made (``tempfile.mkstemp`` returns it after), so that an interruption at any moment
    finds it.

    Parameters
    ----------
    path : Path
        The final destination, beside which the temporary goes.
    directory : bool
        A folder (0700) instead of an empty file (0600).
    """
    temporary = None
    try:
        while temporary is None:
            temporary = path.parent / f".{path.name}.{os.urandom(4).hex()}"
            try:
                if directory:
                    os.mkdir(temporary, 0o700)
                else:
                    os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
            except FileExistsError:
                temporary = None  # another writer's: another name
        yield temporary
    except BaseException:
        if temporary is not None and directory:
            shutil.rmtree(temporary, ignore_errors=True)
        elif temporary is not None:
            temporary.unlink(missing_ok=True)
        raise


@contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success rename it to ``path``.

    Write the file to the yielded path inside the ``with`` block. If the block raises
    (or the process is interrupted by an exception such as KeyboardInterrupt), the
    temporary file is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : path
        Final destination; parent folders are created.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with temporary_beside(path) as temporary:
        yield temporary
        os.chmod(temporary, ordinary_mode())
        sync(temporary)
        os.replace(temporary, path)
    sync(path.parent, directory=True)


def write_text_atomic(text: str, path: str | os.PathLike) -> None:
    """Write ``text`` (UTF-8, line endings as given) to ``path`` atomically.

    Parameters
    ----------
    text : str
        File content.
    path : path
        Destination; parent folders are created.
    """
    with _atomic_text(path) as stream:
        stream.write(text)


@contextmanager
def _atomic_text(path: str | os.PathLike) -> Iterator:
    """A UTF-8 text stream (line endings as written) into :func:`atomic_output`."""
    with (
        atomic_output(path) as temporary,
        open(temporary, "w", encoding="utf-8", newline="") as out,
    ):
        yield out


def write_csv_atomic(table: pd.DataFrame, path: str | os.PathLike) -> None:
    """Write ``table`` as CSV (no index, floats as ``chain.csv_text.FLOAT_FORMAT``,
    ``\\n`` line ends) atomically: an interrupted write never leaves a partial file under
    the final name (:func:`atomic_output`).

    Parameters
    ----------
    table : DataFrame
        Any table.
    path : path
        Destination; parent folders are created.
    """
    from chain.csv_text import csv_chunks  # here: it imports pandas, which a table has loaded

    with _atomic_text(path) as stream:
        stream.writelines(csv_chunks(table))


def replace_folder(staging: Path, out: Path) -> None:
    """Move ``staging`` to ``out``; an existing ``out`` (a dataset) is swapped out first
    and deleted, so a reader sees the old dataset or the new one, never a mixture. The
    files in ``staging`` are written by :func:`atomic_output` (flushed); ``staging``'s
    list of them is flushed before the rename.

    Parameters
    ----------
    staging : Path
        The new dataset's folder, beside ``out``.
    out : Path
        The dataset's final folder.
    """
    sync(staging, directory=True)
    if out.exists():
        old = out.parent / f".{out.name}.old.{os.urandom(4).hex()}"
        os.replace(out, old)
        os.replace(staging, out)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, out)
    sync(out.parent, directory=True)
