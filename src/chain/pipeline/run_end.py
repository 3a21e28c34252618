"""The end of a local Snakemake run: nothing left waiting once its last job is done.

Snakemake (9.x) wakes its scheduler after the job rate limiter's timespan
(``--max-jobs-per-timespan``, 100/1s by default) each time it waits for a running job,
with a ``threading.Timer``, which is not a daemon thread. Python waits for such a timer
before the process exits, so a run that waited for a job ended up to a second after
its last job (measured 1.0-1.5 s from Snakemake's "Complete log" line to its exit: a
what-if, a test's Snakemake call). The timers only wake a scheduler that has stopped
by the time the workflow's ``onsuccess`` or ``onerror`` runs.
"""

from __future__ import annotations

import threading


def cancel_pending_timers() -> int:
    """Cancel every ``threading.Timer`` of this process that has not fired yet, so that
    the process exits at once; call it at the very end of a run (the Snakefile's
    ``onsuccess`` and ``onerror``).

    Returns
    -------
    int
        How many timers were cancelled.
    """
    timers = [t for t in threading.enumerate() if isinstance(t, threading.Timer)]
    for timer in timers:
        timer.cancel()
    return len(timers)
