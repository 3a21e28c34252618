"""chain.pipeline.run.run_end: a process frozen at exit skips the shutdown's collections and
keeps everything else its exit does."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import threading


def _wake(event: threading.Event) -> None:
    event.set()


def test_a_process_frozen_at_exit_keeps_its_exit_handlers_status_and_open_files(tmp_path):
    """freeze_at_exit skips the shutdown's collections: an exit handler registered
    before it runs after it and sees the objects frozen; the exit status is kept; a
    file a module left open is still flushed."""
    code = textwrap.dedent(
        f"""
        import atexit, gc, sys
        from chain.pipeline.run.run_end import freeze_at_exit

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
