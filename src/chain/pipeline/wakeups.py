"""Snakemake's scheduler woken once per wait, not once per event it has ever seen.

Snakemake 9 (read in 9.27) ends each pass of its scheduling loop in which jobs were
ready by starting a ``threading.Timer`` that wakes the loop after the job rate
limiter's timespan (``--max-jobs-per-timespan``, 100/1s by default). The pass such a
timer wakes starts another timer, and every job that starts or ends adds a pass, so
the timers multiply: a local run of the tiny test config (53 jobs, 65 s on 2 cores)
made 1687 passes, each re-reading the size of every ready job's inputs (~45 files: the
code inputs) and solving the job selection again, and Snakemake used 10.3 s of CPU
(106 passes and 4.5 s with one pending wake-up); with 10 000 jobs Snakemake runs out
of threads (snakemake issue #3804).
:func:`coalesce_wakeups` keeps one pending wake-up per scheduler: a pass that finds
one on its way starts none. While jobs wait, a pass still comes at least once per
timespan, which is all the rate limiter needs; the job selection is unchanged.
"""

from __future__ import annotations

import threading

#: The method Snakemake's JobScheduler starts its wake-up timers with (sic).
SNAKEMAKE_METHOD = "_schedule_reevalutation"


def coalesce_wakeups(scheduler_class) -> bool:
    """Make ``scheduler_class`` (Snakemake's ``JobScheduler``) keep at most one pending
    wake-up timer per scheduler, a daemon thread (the process never waits for it).

    Parameters
    ----------
    scheduler_class : type
        The class whose ``_schedule_reevalutation(self, delay)`` (delay in s) starts
        a timer that releases ``self._open_jobs``.

    Returns
    -------
    bool
        Whether it was changed: False when the class has no such method (another
        Snakemake version), which is then left as it is.
    """
    if not callable(getattr(scheduler_class, SNAKEMAKE_METHOD, None)):
        return False

    def schedule_wakeup(self, delay) -> None:
        if getattr(self, "_pending_wakeup", None) is not None:
            return  # one is on its way: it wakes the loop within `delay`
        timer = threading.Timer(delay, _wake, [self])
        timer.daemon = True
        self._pending_wakeup = timer
        timer.start()

    setattr(scheduler_class, SNAKEMAKE_METHOD, schedule_wakeup)
    return True


def _wake(scheduler) -> None:
    # Cleared before the release: the pass it wakes may start the next one.
    scheduler._pending_wakeup = None
    scheduler._open_jobs.release()
