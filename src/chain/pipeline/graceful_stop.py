"""SIGTERM to a Snakemake run: the graceful stop it asks for, never a hang.

Snakemake 9 (read in 9.27.1, the newest release on 27 Nov 2026) handles SIGTERM with
``JobScheduler.exit_gracefully``, which takes the scheduler's lock (a
``threading.Lock``, not reentrant) to note the stop. Python runs a signal handler in
the main thread, between two bytecodes of whatever that thread is doing, and the main
thread itself holds that lock while it selects the next jobs (the ILP solve: a CBC
subprocess, tens of ms per pass) and while it collects the finished ones. A SIGTERM
in that window (``kill PID``; a batch system's cancel or a container stop sends it to
the whole process group) makes the main thread wait for a lock it holds: the run
hangs for good. Seen in tests/test_reproducibility.py's SIGTERM-group rebuild on 27
Nov 2026: Snakemake sat in ``exit_gracefully`` under ``Popen.wait`` of the CBC solver
for 14 min, its jobs already dead, until it was killed.

:func:`stop_gracefully_off_the_main_thread` makes the handler start a thread that
runs Snakemake's own ``exit_gracefully``: that thread waits for the lock as the
executor's callback threads do, the main thread finishes its pass and releases it,
and the stop proceeds as Snakemake means it to (no new job, the running ones finish,
exit 1).
"""

from __future__ import annotations

import functools
import threading

#: The method Snakemake's JobScheduler installs as its SIGTERM handler.
SNAKEMAKE_METHOD = "exit_gracefully"


def stop_gracefully_off_the_main_thread(scheduler_class) -> bool:
    """Make ``scheduler_class`` (Snakemake's ``JobScheduler``) run its SIGTERM handler
    in a thread of its own, so that the signal cannot find the main thread holding the
    lock the handler takes. Call it before the scheduler is made (the Snakefile): the
    scheduler installs the handler as it starts.

    Parameters
    ----------
    scheduler_class : type
        The class whose ``exit_gracefully(self, *args)`` is the SIGTERM handler
        (``args``: the signal number and the interrupted frame).

    Returns
    -------
    bool
        Whether the handler now runs off the main thread (patched by this call or an
        earlier one): False when the class has no such method (another Snakemake
        version), which is then left as it is.
    """
    handler = getattr(scheduler_class, SNAKEMAKE_METHOD, None)
    if not callable(handler) or getattr(handler, "_off_the_main_thread", False):
        return callable(handler)

    @functools.wraps(handler)  # keeps Snakemake's own as __wrapped__
    def exit_gracefully(self, *args) -> None:
        # A daemon: if the run ends before the lock is free, the process does not wait.
        threading.Thread(
            target=handler, args=(self, *args), name="graceful-stop", daemon=True
        ).start()

    exit_gracefully._off_the_main_thread = True
    setattr(scheduler_class, SNAKEMAKE_METHOD, exit_gracefully)
    return True
