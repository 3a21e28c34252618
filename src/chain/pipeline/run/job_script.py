"""A job's script run in this process (workflow/scripts/_job.py, after the store had
no result for it): its exit status as Python's would be, and SIGINT and SIGTERM acting
once."""

from __future__ import annotations

import signal
import sys
import traceback

#: Exit status of a job stopped by a signal: the shell's convention, 128 + signal.
SIGNAL_BASE = 128


def run_script(script: str) -> int:
    """Run ``script`` as this process's ``__main__``; its exit status, as Python's
    would be.

    Parameters
    ----------
    script : str
        A Python file.
    """
    import runpy

    try:
        runpy.run_path(script, run_name="__main__")
    except SystemExit as stop:
        code = stop.code
        if code is None or isinstance(code, int):
            return code or 0
        print(code, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        traceback.print_exc()
        return SIGNAL_BASE + signal.SIGINT
    except BaseException:
        traceback.print_exc()
        return 1
    return 0


def stop_once(signum: int, frame) -> None:
    """Signal handler: end the job as SIGINT (KeyboardInterrupt) or SIGTERM (SystemExit
    with status 128 + signal) do, once; later SIGINT and SIGTERM are ignored, so that a
    signal that arrives twice (sent to a process group, and passed on by a parent)
    cannot cut the atomic writers' clean-up short.
    The scripts' SIGTERM handler too (workflow/scripts/_logging.py).

    Parameters
    ----------
    signum : int
        The signal's number.
    frame : frame or None
        The interrupted frame (unused).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise SystemExit(SIGNAL_BASE + signum)
