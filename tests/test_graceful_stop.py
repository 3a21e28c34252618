"""chain.pipeline.graceful_stop: a SIGTERM that finds Snakemake's main thread holding the
scheduler's lock stops the run instead of hanging it. No clock: the signal is sent
while the lock is held, so it always lands in the window that hung Snakemake; the
test then waits for the stop to be noted, not for a time."""

from __future__ import annotations

import os
import signal
import threading

import pytest

from chain.pipeline.graceful_stop import (
    SNAKEMAKE_METHOD,
    stop_gracefully_off_the_main_thread,
)


class FakeScheduler:
    """What the patch relies on in Snakemake's JobScheduler: a non-reentrant lock that
    the main thread holds while it selects jobs, and a SIGTERM handler that takes it to
    note the stop and then wakes the scheduling loop."""

    def __init__(self):
        self._lock = threading.Lock()
        self._open_jobs = threading.Semaphore(0)
        self._user_kill = None

    def exit_gracefully(self, *args):
        with self._lock:
            self._user_kill = "graceful"
        self._open_jobs.release()


@pytest.fixture
def sigterm_to(request):
    """Install ``scheduler.exit_gracefully`` as this process's SIGTERM handler, as
    Snakemake's scheduler does when it starts; restore the previous one afterwards."""
    previous = signal.getsignal(signal.SIGTERM)
    request.addfinalizer(lambda: signal.signal(signal.SIGTERM, previous))

    def install(scheduler):
        signal.signal(signal.SIGTERM, scheduler.exit_gracefully)

    return install


def test_sigterm_while_the_main_thread_selects_jobs_stops_the_run(sigterm_to):
    """The signal arrives while the main thread holds the lock (the ILP solve): the
    handler returns at once, and once the pass releases the lock the stop is noted
    and the loop is woken, as Snakemake's handler means it to be."""

    class Scheduler(FakeScheduler):
        pass

    assert stop_gracefully_off_the_main_thread(Scheduler)
    scheduler = Scheduler()
    sigterm_to(scheduler)
    with scheduler._lock:  # the main thread selecting jobs
        os.kill(os.getpid(), signal.SIGTERM)  # the handler runs here, in this thread
        assert scheduler._user_kill is None  # not noted yet: the lock is held
    assert scheduler._open_jobs.acquire(timeout=600)  # the loop is woken
    assert scheduler._user_kill == "graceful"


def test_sigterm_at_any_other_time_stops_the_run_as_before(sigterm_to):
    class Scheduler(FakeScheduler):
        pass

    stop_gracefully_off_the_main_thread(Scheduler)
    scheduler = Scheduler()
    sigterm_to(scheduler)
    os.kill(os.getpid(), signal.SIGTERM)
    assert scheduler._open_jobs.acquire(timeout=600)
    assert scheduler._user_kill == "graceful"


def test_patching_twice_wraps_once():
    class Scheduler(FakeScheduler):
        pass

    assert stop_gracefully_off_the_main_thread(Scheduler)
    patched = getattr(Scheduler, SNAKEMAKE_METHOD)
    assert stop_gracefully_off_the_main_thread(Scheduler)
    assert getattr(Scheduler, SNAKEMAKE_METHOD) is patched


def test_a_scheduler_without_the_method_is_left_alone():
    class Other:
        pass

    assert not stop_gracefully_off_the_main_thread(Other)
    assert not hasattr(Other, SNAKEMAKE_METHOD)


def test_snakemakes_scheduler_takes_its_lock_in_the_handler_the_patch_replaces():
    """If a Snakemake release renames the handler, this fails (the patch would do
    nothing); if one stops taking the lock there, the patch can go. (Snakemake's own
    handler is ``__wrapped__`` where a Snakefile read in this process patched it.)"""
    import inspect

    from snakemake.scheduling.job_scheduler import JobScheduler

    handler = getattr(JobScheduler, SNAKEMAKE_METHOD)
    source = inspect.getsource(getattr(handler, "__wrapped__", handler))
    assert "self._lock" in source
    assert f"signal.SIGTERM, self.{SNAKEMAKE_METHOD}" in inspect.getsource(JobScheduler)
