"""chain.pipeline.run_end: a run's process exits as soon as its work is done, not when
a timer Snakemake's scheduler left behind fires (no clock: the timers here would fire
in an hour; the timeouts only guard against a hang)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import threading

from chain.pipeline.run_end import cancel_snakemake_timers


def _wake(event: threading.Event) -> None:
    event.set()


def test_snakemakes_pending_timer_is_cancelled_and_another_is_left_alone():
    """A timer whose function is Snakemake's (as its scheduler's wake-up is) is
    cancelled and never fires; one of other code keeps running."""
    fired, other = threading.Event(), threading.Event()

    def snakemake_wake_up():
        fired.set()

    snakemake_wake_up.__module__ = "snakemake.scheduling.job_scheduler"
    theirs = threading.Timer(3600.0, snakemake_wake_up)
    ours = threading.Timer(3600.0, _wake, [other])
    theirs.start()
    ours.start()
    try:
        assert cancel_snakemake_timers() == 1
        theirs.join(timeout=60)
        assert not theirs.is_alive() and not fired.is_set()
        assert ours.is_alive()
    finally:
        ours.cancel()


def test_a_process_with_snakemakes_pending_timer_exits_once_it_is_cancelled():
    """Python waits for a non-daemon timer before it exits (the Snakemake scheduler's
    own, at the end of every run that waited for a job)."""
    code = textwrap.dedent(
        """
        import threading
        from chain.pipeline.run_end import cancel_snakemake_timers
        def wake_up():
            print("fired")
        wake_up.__module__ = "snakemake.scheduling.job_scheduler"
        threading.Timer(3600.0, wake_up).start()
        print(cancel_snakemake_timers())
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["1"]


def test_a_process_frozen_at_exit_keeps_its_exit_handlers_status_and_open_files(tmp_path):
    """freeze_at_exit skips the shutdown's collections: an exit handler registered
    before it runs after it and sees the objects frozen; the exit status is kept; a
    file a module left open is still flushed."""
    code = textwrap.dedent(
        f"""
        import atexit, gc, sys
        from chain.pipeline.run_end import freeze_at_exit

        atexit.register(lambda: print("frozen", gc.get_freeze_count() > 0, flush=True))
        freeze_at_exit()
        freeze_at_exit()  # once is enough
        stream = open({str(tmp_path / "left_open.txt")!r}, "w")
        stream.write("buffered")
        sys.exit(3)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 3, done.stderr
    assert done.stdout.split() == ["frozen", "True"]
    assert (tmp_path / "left_open.txt").read_text() == "buffered"
