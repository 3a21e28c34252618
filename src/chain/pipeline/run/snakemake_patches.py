"""Two defects of Snakemake's scheduler that a run of this workflow meets, patched from
the Snakefile until Snakemake fixes them; each is written up, with a reproducer that
needs no part of this workflow, in ``docs/upstream/README.md``:

* **wake-ups multiply** (:func:`coalesce_wakeups`): every pass of the scheduling loop
  with ready jobs starts a timer that starts another pass (snakemake/snakemake#3804);
* **SIGTERM hangs the run** (:func:`stop_gracefully_off_the_main_thread`): the handler
  waits for the lock the main thread holds while it selects jobs.

The patches replace private methods of the scheduler, so they are applied only on the
release they were written for (:data:`WRITTEN_FOR`, the locks'); on any other
:func:`patch_snakemake` leaves Snakemake as it is and says so in one line.
"""

from __future__ import annotations

import functools
import threading

#: The Snakemake release whose scheduler these patches were written for (and tested
#: against: requirements/*.lock pin it).
WRITTEN_FOR = "9.27.1"

#: The JobScheduler methods the patches replace (sic: Snakemake's spelling).
WAKEUP_METHOD = "_schedule_reevalutation"
SIGTERM_METHOD = "exit_gracefully"

#: What a run does without each patch (said when a patch does not apply).
UNPATCHED = {
    WAKEUP_METHOD: "the scheduler's wake-up timers multiply (more CPU in Snakemake's "
    "process, up to 1 s of waiting at its exit)",
    SIGTERM_METHOD: "a SIGTERM (kill PID, a batch system's cancel) may hang the run "
    "while Snakemake selects jobs",
}


def coalesce_wakeups(scheduler_class) -> bool:
    """Make ``scheduler_class`` (Snakemake's ``JobScheduler``) keep at most one pending
    wake-up timer per scheduler, a daemon thread. While jobs wait, a pass still comes
    once per timespan, which is all the rate limiter needs; the selection is unchanged.

    ``scheduler_class``'s ``_schedule_reevalutation(self, delay)`` (delay in s) starts
    a timer that releases ``self._open_jobs``. Returns whether it was changed (False: no
    such method, left as it is).
    """
    original = getattr(scheduler_class, WAKEUP_METHOD, None)
    if not callable(original):
        return False

    @functools.wraps(original)  # keeps Snakemake's own as __wrapped__
    def schedule_wakeup(self, delay) -> None:
        if getattr(self, "_pending_wakeup", None) is not None:
            return  # one is on its way: it wakes the loop within `delay`
        timer = threading.Timer(delay, _wake, [self])
        timer.daemon = True
        self._pending_wakeup = timer
        timer.start()

    setattr(scheduler_class, WAKEUP_METHOD, schedule_wakeup)
    return True


def _wake(scheduler) -> None:
    # Cleared before the release: the pass it wakes may start the next one.
    scheduler._pending_wakeup = None
    scheduler._open_jobs.release()


def stop_gracefully_off_the_main_thread(scheduler_class) -> bool:
    """Make ``scheduler_class`` run its SIGTERM handler in a thread of its own, which
    waits for the lock as the executor's callback threads do; the main thread finishes
    its pass, and the stop proceeds as Snakemake means it to (no new job, the running
    ones finish, exit 1). Call it before the scheduler is made (it installs the handler
    as it starts). ``scheduler_class``'s ``exit_gracefully(self, *args)`` is the SIGTERM
    handler; returns whether it now runs off the main thread (False: no such method).
    """
    handler = getattr(scheduler_class, SIGTERM_METHOD, None)
    if not callable(handler) or getattr(handler, "_off_the_main_thread", False):
        return callable(handler)

    @functools.wraps(handler)  # keeps Snakemake's own as __wrapped__
    def exit_gracefully(self, *args) -> None:
        # A daemon: if the run ends before the lock is free, the process does not wait.
        threading.Thread(
            target=handler, args=(self, *args), name="graceful-stop", daemon=True
        ).start()

    exit_gracefully._off_the_main_thread = True
    setattr(scheduler_class, SIGTERM_METHOD, exit_gracefully)
    return True


def patch_snakemake(scheduler_class, version: str) -> list[str]:
    """Apply both patches to ``scheduler_class`` on the Snakemake release they were
    written for; the console's lines: none then, else one saying they are off.

    Parameters
    ----------
    scheduler_class : type
        ``snakemake.scheduling.job_scheduler.JobScheduler``.
    version : str
        The running Snakemake's version.
    """
    if version != WRITTEN_FOR:
        return [
            f"hertzchain: Snakemake {version}: the scheduler patches written for "
            f"{WRITTEN_FOR} stay off ({'; '.join(UNPATCHED.values())}; "
            "docs/upstream/README.md)"
        ]
    coalesce_wakeups(scheduler_class)
    stop_gracefully_off_the_main_thread(scheduler_class)
    return []
