"""The end of a workflow process: no time spent tearing down what the OS reclaims.

A process that has imported Snakemake (sqlalchemy, pydantic: ~1500 modules) or a job's
libraries (pandas, scipy, numba, matplotlib) spends 0.25-0.5 s in Python's own
shutdown, most of it in the garbage collections that run as the modules are torn down
(0.03-0.06 s without them). :func:`freeze_at_exit` skips those collections: every
Snakemake process of the workflow (a run's, each cluster job's) and every job that runs
in its own process.
"""

from __future__ import annotations

import atexit
import gc


def freeze_at_exit() -> None:
    """When this process exits (among its ``atexit`` handlers, all of which still
    run), move every object then alive into the collector's permanent generation
    (``gc.freeze``), so that the collections of the interpreter's shutdown skip them.

    The shutdown still clears the modules (a file a module left open is flushed), but
    objects in reference cycles are no longer finalized: a file held only by a cycle
    and never closed would lose what it buffered. So it is for processes whose writes
    are closed as they end (the workflow's: Snakemake's metadata and logs, the atomic
    writers of the jobs' results), and the operating system reclaims the rest. Calling
    it again adds nothing.
    """
    atexit.unregister(gc.freeze)
    atexit.register(gc.freeze)
