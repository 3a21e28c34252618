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
"""

from __future__ import annotations

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
