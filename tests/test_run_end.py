"""chain.pipeline.run_end: a run's process exits as soon as its work is done, not when
a timer Snakemake's scheduler left behind fires (no clock: the timer here would fire in
an hour; the timeouts only guard against a hang)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import threading

from chain.pipeline.run_end import cancel_pending_timers


def test_a_pending_timer_is_cancelled_and_never_fires():
    fired = threading.Event()
    timer = threading.Timer(3600.0, fired.set)
    timer.start()
    assert cancel_pending_timers() >= 1
    timer.join(timeout=60)
    assert not timer.is_alive() and not fired.is_set()


def test_a_process_with_a_pending_timer_exits_once_it_is_cancelled():
    """Python waits for a non-daemon timer before it exits (the Snakemake scheduler's
    own, at the end of every run that waited for a job)."""
    code = textwrap.dedent(
        """
        import threading
        from chain.pipeline.run_end import cancel_pending_timers
        threading.Timer(3600.0, print, ["fired"]).start()
        print(cancel_pending_timers())
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["1"]
