"""The end of a local Snakemake run: nothing left waiting once its last job is done.

Snakemake (9.x) wakes its scheduler after the job rate limiter's timespan
(``--max-jobs-per-timespan``, 100/1s by default) each time it waits for a running job,
with a ``threading.Timer``, which is not a daemon thread. Python waits for such a timer
before the process exits, so a run that waited for a job ended up to a second after
its last job (measured 1.0-1.5 s from Snakemake's "Complete log" line to its exit: a
what-if, a test's Snakemake call). The timers only wake a scheduler that has stopped
by the time the workflow's ``onsuccess`` or ``onerror`` runs. The workflow replaces
those timers by a single daemon one (:mod:`chain.pipeline.wakeups`); this stays for a
Snakemake whose scheduler that patch does not recognise.

A process that has imported Snakemake (sqlalchemy, pydantic: ~1500 modules) or a job's
libraries (pandas, scipy, numba, matplotlib) then spends 0.25-0.5 s in Python's own
shutdown, most of it in the garbage collections that run as the modules are torn down
(0.03-0.06 s without them; measured on this machine). :func:`freeze_at_exit` skips
those collections: every Snakemake process of the workflow (a run's, each cluster
job's) and every job that runs in its own process.
"""

from __future__ import annotations

import atexit
import gc
import threading

#: Whose timers are cancelled: Snakemake's (its scheduler's wake-ups), not those of
#: whatever else runs in the process (a notebook driving Snakemake's API).
SNAKEMAKE_PACKAGE = "snakemake"


def cancel_snakemake_timers() -> int:
    """Cancel every ``threading.Timer`` that Snakemake's code started in this process
    and that has not fired yet, so that the process exits at once; call it at the very
    end of a run (the Snakefile's ``onsuccess`` and ``onerror``). Timers of other code
    are left alone.

    Returns
    -------
    int
        How many timers were cancelled.
    """
    cancelled = 0
    for thread in threading.enumerate():
        if isinstance(thread, threading.Timer) and _started_by_snakemake(thread):
            thread.cancel()
            cancelled += 1
    return cancelled


def _started_by_snakemake(timer: threading.Timer) -> bool:
    module = getattr(timer.function, "__module__", None) or ""
    return module == SNAKEMAKE_PACKAGE or module.startswith(f"{SNAKEMAKE_PACKAGE}.")


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
