"""A job as Snakemake runs it (workflow/scripts/_job.py first, then the script, in a
fresh interpreter on a copy of the script whose preamble sets ``snakemake``): its
outputs, streams and exit status are the script's own, a failure shows its traceback,
and SIGINT or SIGTERM stops it with the status a shell reports, its temporary files
removed. The store's part of a job: test_reuse.py and the workflow tests."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Snakemake's preamble, reduced to what _job reads: a job with no outputs whose config
#: turns reuse off, and the file it runs.
PREAMBLE = (
    "import sys; sys.path.extend([{scripts!r}])\n"
    "class _L(list):\n    def items(self): return []\n"
    "class snakemake:\n    rule = 'test'; config = {{'run_name': 'test', 'reuse': False}}\n"
    "    wildcards = params = input = output = log = _L()\n"
    "__real_file__ = __file__\n"
)

SCRIPTS = {
    # A result through the atomic writer, a line on each stream, a chosen status.
    "compute": """
import _job  # noqa: F401
import os
import sys

import pandas as pd

from chain.atomic import write_csv_atomic

write_csv_atomic(pd.DataFrame({"x": [1.5, 2.5]}), "out/table.csv")
print("to stdout")
print("to stderr", file=sys.stderr)
sys.exit(int(os.environ.get("JOB_STATUS", "0")))
""",
    "failing": """
import _job  # noqa: F401

raise ValueError("a bad input, named")
""",
    # Writes its pid, then waits in the middle of an atomic write until signalled.
    "waiting": """
import _job  # noqa: F401
import os
import signal
import time

from chain.atomic import atomic_output
from chain.pipeline.run.job_script import stop_once

signal.signal(signal.SIGTERM, stop_once)  # as the scripts' _logging.start does
with atomic_output("out/result.txt") as temporary:
    temporary.write_text("partial")
    with open("out/pid.txt", "w") as stream:
        stream.write(str(os.getpid()))
    while True:
        time.sleep(0.05)
""",
}


@pytest.fixture
def work(tmp_path) -> Path:
    """A scripts folder (_job and the jobs above) and a working directory."""
    scripts = tmp_path / "scripts"
    scripts.mkdir()
    shutil.copy2(ROOT / "workflow" / "scripts" / "_job.py", scripts)
    for name, text in SCRIPTS.items():
        copy = tmp_path / "work" / f".job.{name}.py"
        copy.parent.mkdir(exist_ok=True)
        copy.write_text(PREAMBLE.format(scripts=str(scripts)) + text)
    (tmp_path / "work" / "out").mkdir()
    return tmp_path / "work"


def start(work: Path, name: str, **env) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, str(work / f".job.{name}.py")],
        cwd=work,
        env={**os.environ, **env},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_default_signals,
    )


def _default_signals() -> None:
    # A background shell starts pytest with SIGINT ignored, kept across exec.
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def test_a_job_gives_its_scripts_outputs_streams_and_status(work):
    job = start(work, "compute", JOB_STATUS="3")
    out, err = job.communicate(timeout=600)
    assert job.returncode == 3, err
    assert (out, err) == ("to stdout\n", "to stderr\n")
    assert (work / "out" / "table.csv").read_text() == "x\n1.5\n2.5\n"


def test_a_failing_job_fails_with_its_traceback(work):
    job = start(work, "failing")
    _, err = job.communicate(timeout=600)
    assert job.returncode == 1
    assert "ValueError: a bad input, named" in err and "Traceback" in err


@pytest.mark.parametrize(
    ("signum", "status"),
    [(signal.SIGTERM, 128 + signal.SIGTERM), (signal.SIGINT, 128 + signal.SIGINT)],
    ids=["SIGTERM", "SIGINT"],
)
def test_a_signal_stops_the_job_cleanly(work, signum, status):
    """SIGTERM (a batch system's cancel) or SIGINT: the status of a job stopped so,
    and no temporary file left."""
    job = start(work, "waiting")
    pid_file = work / "out" / "pid.txt"
    deadline = time.monotonic() + 600
    while not (pid_file.exists() and pid_file.read_text()):
        assert job.poll() is None, job.communicate()[1]
        assert time.monotonic() < deadline, "the job did not start"
        time.sleep(0.02)
    job.send_signal(signum)
    job.communicate(timeout=600)
    assert job.returncode == status
    assert sorted(p.name for p in (work / "out").iterdir()) == ["pid.txt"]
