"""chain.pipeline.wakeups: Snakemake's scheduler keeps one pending wake-up, not one
more per pass (no clock: a pending timer here would fire in an hour; the one that
fires does so at once, and the test waits for its release, not for a time)."""

from __future__ import annotations

import threading

from chain.pipeline.wakeups import SNAKEMAKE_METHOD, coalesce_wakeups


class FakeScheduler:
    """What the patch relies on in Snakemake's JobScheduler: a semaphore that wakes the
    loop, and the method that starts a timer releasing it."""

    def __init__(self):
        self._open_jobs = threading.Semaphore(0)
        self.started = []

    def _schedule_reevalutation(self, delay):
        timer = threading.Timer(delay, self._open_jobs.release)
        self.started.append(timer)
        timer.start()


def _ours(scheduler) -> list[threading.Timer]:
    return [t for t in threading.enumerate() if t is getattr(scheduler, "_pending_wakeup", 0)]


def test_many_passes_leave_one_pending_wakeup_that_is_a_daemon():
    """Fifty passes that each ask for a wake-up in an hour start one timer, a daemon
    (the process does not wait for it), and none of Snakemake's own."""

    class Scheduler(FakeScheduler):
        pass

    assert coalesce_wakeups(Scheduler)
    scheduler = Scheduler()
    for _ in range(50):
        getattr(scheduler, SNAKEMAKE_METHOD)(3600.0)
    try:
        pending = _ours(scheduler)
        assert len(pending) == 1 and pending[0].daemon
        assert scheduler.started == []
    finally:
        scheduler._pending_wakeup.cancel()


def test_a_wakeup_that_fired_lets_the_pass_it_woke_start_the_next():
    """The timer releases the loop's semaphore once, and is no longer pending by then:
    the pass it wakes starts a new one (a scheduler whose jobs wait is woken again)."""

    class Scheduler(FakeScheduler):
        pass

    coalesce_wakeups(Scheduler)
    scheduler = Scheduler()
    getattr(scheduler, SNAKEMAKE_METHOD)(0.0)
    assert scheduler._open_jobs.acquire(timeout=600)  # the wake-up came
    assert scheduler._pending_wakeup is None
    getattr(scheduler, SNAKEMAKE_METHOD)(3600.0)
    try:
        assert len(_ours(scheduler)) == 1
        assert not scheduler._open_jobs.acquire(blocking=False)  # released once only
    finally:
        scheduler._pending_wakeup.cancel()


def test_a_scheduler_without_the_method_is_left_alone():
    class Other:
        pass

    assert not coalesce_wakeups(Other)
    assert not hasattr(Other, SNAKEMAKE_METHOD)


def test_snakemakes_scheduler_has_the_method_the_patch_replaces():
    """If a Snakemake release renames it, this fails (the patch would do nothing)."""
    from snakemake.scheduling.job_scheduler import JobScheduler

    assert callable(getattr(JobScheduler, SNAKEMAKE_METHOD, None))
