"""The job server (chain.pipeline.job_server): a job handed to it runs as it would in
its own process (same outputs, streams, directory, environment, exit status), and the
signals a job's process gets (Ctrl-C, a batch system's SIGTERM, a crash) end the work
as they did, leaving no temporary file; with no server the job runs where it is.

Each test starts a server on a folder of small scripts written like the workflow's
(``import _hand_off`` first) and runs them as Snakemake does: a fresh interpreter on a
copy of the script whose preamble sets ``snakemake`` (a job with no outputs, reuse off:
the store is test_reuse's business) and ``__real_file__``. Only the server's owner can
hand it a job (its socket's folder, its check of the peer's uid), and a job from another
environment runs in its own. That the workflow's own
results do not depend on the server is the workflow tests' business: test_workflow's
recompute runs without it, test_reproducibility's first build too.
"""

from __future__ import annotations

import os
import select
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from chain.pipeline.job_server import ADDRESS_VARIABLE

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux sockets")

#: A job like the workflow's: numpy and pandas imported after the hand-off, a result
#: written through the atomic writer, a line on stdout and one on stderr, and what the
#: process is (its parent, directory, an environment variable) in the output.
COMPUTE = """
import _hand_off  # noqa: F401
import os
import sys

import numpy as np
import pandas as pd

from chain.atomic import write_csv_atomic

values = np.random.default_rng(7).normal(size=50).cumsum()
write_csv_atomic(pd.DataFrame({"x": values}), "out/table.csv")
with open("out/process.txt", "w") as stream:
    print(os.getppid(), os.getcwd(), os.environ.get("JOB_VALUE"), file=stream)
print("to stdout")
print("to stderr", file=sys.stderr)
sys.exit(int(os.environ.get("JOB_STATUS", "0")))
"""

#: A job that fails with a traceback.
FAILING = """
import _hand_off  # noqa: F401

raise ValueError("a bad input, named")
"""

#: A job that writes its pid, then waits in the middle of an atomic write until
#: signalled; the atomic writer removes its temporary file on the way out.
WAITING = """
import _hand_off  # noqa: F401
import os
import time

from chain.atomic import atomic_output

with atomic_output("out/result.txt") as temporary:
    temporary.write_text("partial")
    with open("out/pid.txt", "w") as stream:
        stream.write(str(os.getpid()))
    while True:
        time.sleep(0.05)
"""


#: Snakemake's preamble, reduced to what _hand_off reads: a job with no outputs whose
#: config turns reuse off, and the file it runs.
PREAMBLE = (
    "import sys; sys.path.extend([{scripts!r}])\n"
    "class _L(list):\n    def items(self): return []\n"
    "class snakemake:\n    rule = 'test'; config = {{'run_name': 'test', 'reuse': False}}\n"
    "    wildcards = params = input = output = log = _L()\n"
    "__real_file__ = __file__\n"
)


@pytest.fixture
def scripts(tmp_path) -> Path:
    """The scripts folder: the hand-off helper and the jobs above."""
    folder = tmp_path / "scripts"
    folder.mkdir()
    shutil.copy2(ROOT / "workflow" / "scripts" / "_hand_off.py", folder)
    for name, text in {"compute": COMPUTE, "failing": FAILING, "waiting": WAITING}.items():
        (folder / f"{name}.py").write_text(text)
    (tmp_path / "work" / "out").mkdir(parents=True)
    return folder


def private_address() -> str:
    """A socket path in a new folder only this user may enter, as the workflow's."""
    return os.path.join(tempfile.mkdtemp(prefix="hertzchain-test-"), "socket")


def start_server(scripts: Path, until: str, **env) -> tuple[str, subprocess.Popen, list]:
    """A job server for ``scripts`` started with ``env`` added to this environment;
    (address, process, the lines it printed) once it printed a line starting ``until``."""
    address = private_address()
    process = subprocess.Popen(
        [sys.executable, "-m", "chain.pipeline.job_server", address, str(scripts)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, **env},
    )
    lines = []
    while not (lines and lines[-1].startswith(until)):
        lines.append(process.stdout.readline())
        if not lines[-1]:
            process.wait(timeout=30)
            raise AssertionError(f"the server ended before {until!r}:\n" + "".join(lines))
    return address, process, lines


@pytest.fixture
def server(scripts, tmp_path):
    """A running job server for ``scripts``; (address, process). Ready when it says so
    (it binds before it imports, so a job never races its start)."""
    address, process, _ = start_server(scripts, "job server: ready")
    yield address, process
    process.terminate()
    process.wait(timeout=30)
    shutil.rmtree(Path(address).parent, ignore_errors=True)


def job(scripts: Path, name: str, address: str, tmp_path: Path, **env) -> list[str]:
    """The command and environment of a job as Snakemake runs it: the script copied
    with a preamble that sets ``__real_file__``."""
    copy = tmp_path / "work" / f".job.{name}.py"
    copy.write_text(PREAMBLE.format(scripts=str(scripts)) + (scripts / f"{name}.py").read_text())
    environment = {**os.environ, ADDRESS_VARIABLE: address, **env}
    return [sys.executable, str(copy)], environment


def run_job(scripts, name, address, tmp_path, **env) -> subprocess.CompletedProcess:
    command, environment = job(scripts, name, address, tmp_path, **env)
    return subprocess.run(
        command, cwd=tmp_path / "work", env=environment, capture_output=True, text=True
    )


def test_a_job_in_the_server_gives_what_its_own_process_gives(scripts, server, tmp_path):
    """Same table bytes, streams, directory, environment and exit status; only the
    parent differs (the server, not the job's own process)."""
    address, process = server
    out = tmp_path / "work" / "out"
    results = {}
    for where in ("off", address):
        result = run_job(scripts, "compute", where, tmp_path, JOB_VALUE="42", JOB_STATUS="3")
        parent, cwd, value = (out / "process.txt").read_text().split()
        results[where] = (result, (out / "table.csv").read_bytes(), parent, cwd, value)
    alone, served = results["off"], results[address]
    assert served[2] == str(process.pid) and alone[2] != str(process.pid)
    for result, table, _, cwd, value in (alone, served):
        assert result.returncode == 3, result.stderr
        assert (result.stdout, result.stderr) == ("to stdout\n", "to stderr\n")
        assert cwd == str(tmp_path / "work") and value == "42"
        assert table == alone[1]


def test_a_failing_job_fails_with_its_traceback(scripts, server, tmp_path):
    address, _ = server
    result = run_job(scripts, "failing", address, tmp_path)
    assert result.returncode == 1
    assert "ValueError: a bad input, named" in result.stderr and "Traceback" in result.stderr


def test_without_a_server_the_job_runs_in_its_own_process(scripts, tmp_path):
    """An address nobody listens at (a server that is gone): the job runs here."""
    result = run_job(scripts, "compute", "hertzchain-test-nobody", tmp_path)
    assert result.returncode == 0, result.stderr
    parent = (tmp_path / "work" / "out" / "process.txt").read_text().split()[0]
    assert parent == str(os.getpid())


#: A helper module imported by the preload, in the server: its import returns once a
#: job waits at the server's socket (the only socket the server has then). In a job it
#: is already imported (the job is forked from the server) or, run alone, not waited on.
GATE = """
import os
import select
import stat
import sys

if os.environ.get("GATE_IN_SERVER") == "1" and "_hand_off" not in sys.modules:
    sockets = []
    for name in os.listdir("/proc/self/fd"):
        try:
            if stat.S_ISSOCK(os.fstat(int(name)).st_mode):
                sockets.append(int(name))
        except OSError:
            pass
    print("gate: waiting for a job", flush=True)
    select.select(sockets, [], [])
"""

#: A job that says which of the preload's modules were imported when it started: the
#: gate (imported just before it was forked) and the module after it (not yet).
EARLY = """
import _hand_off  # noqa: F401
import sys

print("gate" in sys.modules, "zz_after_gate" in sys.modules)

import gate  # noqa: E402,F401
import zz_after_gate  # noqa: E402,F401
"""


def test_a_job_does_not_wait_for_the_whole_preload(scripts, tmp_path):
    """The server serves a job between two of its preload's imports: a job that arrives
    while the preload runs is forked with what is imported so far (the gate module,
    whose import in the server ends when the job is waiting) and imports the rest
    itself, before the server has imported the module after the gate or said it is
    ready. No clock: the gate waits for the job, not for a time."""
    (scripts / "gate.py").write_text(GATE)
    (scripts / "zz_after_gate.py").write_text("")
    (scripts / "early.py").write_text(EARLY)
    address, process, lines = start_server(scripts, "gate: waiting", GATE_IN_SERVER="1")
    try:
        result = run_job(scripts, "early", address, tmp_path)
        assert result.returncode == 0, result.stderr
        assert result.stdout.split() == ["True", "False"]
        lines.append(process.stdout.readline())
        while lines[-1] and not lines[-1].startswith("job server: ready"):
            lines.append(process.stdout.readline())
        assert lines[-1].startswith("job server: ready"), "".join(lines)
    finally:
        process.terminate()
        process.wait(timeout=30)


def gone(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    # A zombie is gone for our purpose (the server's children are reaped by the kernel,
    # SIGCHLD ignored, but this reads /proc in case).
    status = Path(f"/proc/{pid}/status")
    return status.exists() and "zombie" in status.read_text()


def started(scripts, address, tmp_path) -> tuple[subprocess.Popen, int]:
    """The waiting job, started in the server; (its client's process, the child's pid)
    once the child is inside its atomic write."""
    command, environment = job(scripts, "waiting", address, tmp_path)
    client = subprocess.Popen(
        command, cwd=tmp_path / "work", env=environment, preexec_fn=_default_signals
    )
    pid_file = tmp_path / "work" / "out" / "pid.txt"
    deadline = time.monotonic() + 120
    while not (pid_file.exists() and pid_file.read_text()):
        assert client.poll() is None, "the job ended before it started waiting"
        assert time.monotonic() < deadline, "the job did not start"
        time.sleep(0.02)
    return client, int(pid_file.read_text())


def _default_signals() -> None:
    # A background shell starts pytest with SIGINT ignored, and an ignored signal stays
    # ignored across exec (tests/test_reproducibility.py does the same).
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, signal.SIG_DFL)


def wait_gone(pid: int) -> None:
    deadline = time.monotonic() + 60
    while not gone(pid):
        assert time.monotonic() < deadline, f"process {pid} still running"
        time.sleep(0.02)


@pytest.mark.parametrize(
    ("signum", "status"),
    [(signal.SIGTERM, 128 + signal.SIGTERM), (signal.SIGINT, 128 + signal.SIGINT)],
    ids=["SIGTERM", "SIGINT"],
)
def test_a_signal_to_the_jobs_process_stops_the_job_cleanly(
    scripts, server, tmp_path, signum, status
):
    """SIGTERM (a batch system's cancel) or SIGINT to the job's process: the job stops
    with the status of a job stopped so, and its temporary file is gone."""
    address, process = server
    client, child = started(scripts, address, tmp_path)
    assert child != client.pid
    client.send_signal(signum)
    assert client.wait(timeout=60) == status
    wait_gone(child)
    assert sorted(p.name for p in (tmp_path / "work" / "out").iterdir()) == ["pid.txt"]
    assert process.poll() is None  # the server serves on


def test_a_killed_jobs_process_takes_its_work_with_it(scripts, server, tmp_path):
    """SIGKILL to the job's process (the OOM killer): its child in the server is stopped
    and cleans up; nothing runs on for a job Snakemake thinks is over."""
    address, _ = server
    client, child = started(scripts, address, tmp_path)
    client.kill()
    client.wait(timeout=60)
    wait_gone(child)
    assert sorted(p.name for p in (tmp_path / "work" / "out").iterdir()) == ["pid.txt"]


def test_the_server_ends_with_the_process_that_started_it(scripts, tmp_path):
    """Snakemake killed alone (its process group spared): the server does not linger."""
    address = private_address()
    starter = subprocess.run(
        [
            sys.executable,
            "-c",
            "import subprocess, sys; p = subprocess.Popen([sys.executable, '-m', "
            f"'chain.pipeline.job_server', {address!r}, {str(scripts)!r}], "
            "stdout=subprocess.PIPE, text=True); print(p.pid, flush=True); "
            "p.stdout.readline()",
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert starter.returncode == 0, starter.stderr
    wait_gone(int(starter.stdout.split()[0]))


def test_a_job_that_integrates_has_the_kernels_loaded_before_it_starts(tmp_path, monkeypatch):
    """numba's cached kernels are loaded before each job whose script runs them, by
    whatever path of the library (the simulations import them through
    ``chain.apparatus``), never for one that does not (Fig. 4 imports the closed forms
    of ``chain.physics``, no kernel: an analysis what-if integrates nothing)."""
    from chain.pipeline import preload

    calls: list[str] = []
    monkeypatch.setattr(preload, "_load_cached_kernels", lambda: calls.append("load") or 0)
    jobs = {
        "figure": "import pandas\nimport chain.report.figures\n",
        "closed_forms": "from chain.physics.theory import ballistic_constants\n",
        "fields": "from chain.physics.simulation import simulate\n",
        "shots": "from chain.apparatus.shots import simulate_shots\n",
    }
    for name, imports in jobs.items():
        (tmp_path / f"{name}.py").write_text(f"import _hand_off\n{imports}")

    loads = {}
    for name in jobs:
        calls.clear()
        preload.load_kernels_for(str(tmp_path / f"{name}.py"))
        loads[name] = len(calls)
    assert loads == {"figure": 0, "closed_forms": 0, "fields": 1, "shots": 1}
    assert "chain.physics.kernels" in sys.modules
    # Asked again for each job: a run's later jobs get what its first ones compiled.
    calls.clear()
    preload.load_kernels_for(str(tmp_path / "shots.py"))
    assert calls == ["load"]


def test_the_preload_imports_the_preamble_first_and_ends_ready(capsys):
    """The workflow's own preload, step by step as the server runs it: Snakemake's
    preamble's imports first (every job's process runs them before its script), then
    the scripts' imports, the figures' warm-up in its three steps (the scripts draw
    figures) and the ready line last."""
    from chain.pipeline import preload

    names, preamble = [], []
    for step in preload.preload_steps(ROOT / "workflow" / "scripts", "address"):
        names.append(step.__name__)
        if len(preamble) < len(preload.PREAMBLE_IMPORTS):
            preamble.append(step.__closure__[0].cell_contents)
        step()
    assert preamble == list(preload.PREAMBLE_IMPORTS)
    assert names[-4:] == ["warm_up", "warm_up", "warm_up", "ready"]
    assert set(names[:-4]) == {"step"}
    assert capsys.readouterr().out == "job server: ready at address\n"  # nothing failed


def test_the_server_loads_what_the_library_defers_from_a_scripts_second_job(tmp_path):
    """chain.analysis.pulses imports scipy.signal inside find_pulses: the first job of
    a script that reaches it is forked without it (it imports what it calls itself),
    the second with it loaded (in a fresh interpreter, as the server is)."""
    script = (ROOT / "workflow" / "scripts" / "pulses.py").read_text()
    first, second = tmp_path / "tmp1a.pulses.py", tmp_path / "tmp2b.pulses.py"
    first.write_text(script)
    second.write_text(script)
    check = (
        "import sys, scipy\n"
        "from chain.pipeline import preload\n"
        f"preload.load_deferred_imports_for({str(first)!r})\n"
        "print('scipy.signal' in sys.modules)\n"
        f"preload.load_deferred_imports_for({str(second)!r})\n"
        "print('scipy.signal' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", check], capture_output=True, text=True, cwd=ROOT, timeout=300
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "True"]


def test_deferred_imports_are_those_in_functions_of_loaded_packages(tmp_path):
    """What a file imports inside a function, not at its top; of a package loaded
    (scipy), not of one nothing loaded (lammps, an extra that starts MPI); not what is
    loaded already (json)."""
    from chain.pipeline.preload import deferred_imports

    module = tmp_path / "fake.py"
    module.write_text(
        "import scipy.optimize\n\n\ndef f():\n    from scipy.signal import find_peaks\n"
        "    import lammps\n    import json\n\n\nclass A:\n"
        "    def g(self):\n        import scipy.ndimage\n"
    )
    loaded = {"scipy", "json"}
    assert deferred_imports([module], loaded) == ["scipy.ndimage", "scipy.signal"]
    assert deferred_imports([module], loaded | {"scipy.signal"}) == ["scipy.ndimage"]
    assert deferred_imports([tmp_path / "missing.py"], loaded) == []


#: A job that says where it runs: its interpreter's prefix, and its parent.
WHERE = """
import _hand_off  # noqa: F401
import os
import sys

with open("out/where.txt", "w") as stream:
    print(sys.prefix, os.getppid(), file=stream)
"""


def test_a_job_from_another_environment_runs_in_its_own(scripts, server, tmp_path):
    """A job whose interpreter is another virtual environment's (``--sdm conda``, a
    container) runs in its own process with that interpreter, not in the server, which
    lives in this environment; the same job from this environment runs in the server."""
    address, process = server
    (scripts / "where.py").write_text(WHERE)
    other = tmp_path / "other-venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", other], check=True)
    command, environment = job(scripts, "where", address, tmp_path)
    environment["PYTHONPATH"] = str(ROOT / "src")  # the library, not the packages
    where = {}
    for python in (other / "bin" / "python", sys.executable):
        done = subprocess.run(
            [str(python), *command[1:]], cwd=tmp_path / "work", env=environment, timeout=300
        )
        assert done.returncode == 0
        where[str(python)] = (tmp_path / "work" / "out" / "where.txt").read_text().split()
    assert where[str(other / "bin" / "python")] == [str(other), str(os.getpid())]
    assert where[sys.executable] == [sys.prefix, str(process.pid)]


#: Another user's attempt (stdlib only): connect, send a request as a client would,
#: and say what came back.
INTRUDER = """
import json, socket, struct, sys
connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
try:
    connection.connect(sys.argv[1])
except PermissionError:
    print("no entry")
    raise SystemExit
request = json.dumps({"script": sys.argv[2], "cwd": "/", "env": {}, "path": []}).encode()
try:
    socket.send_fds(connection, [struct.pack("!Q", len(request))], [0, 1, 2])
    connection.sendall(request)
    print("refused" if connection.recv(8) == b"" else "ran")
except (BrokenPipeError, ConnectionResetError):  # closed before it read a byte
    print("refused")
"""


def test_another_user_cannot_hand_the_server_a_job(scripts, server, tmp_path):
    """As uid 65534 (nobody): the socket's folder cannot be entered; opened on purpose,
    the server still refuses the connection by its peer's uid, before reading it."""
    if os.getuid() != 0:
        pytest.skip("needs root to act as another user (uid 65534): not checked here")
    python = _python_for(65534)
    address, process = server
    folder = Path(address).parent
    assert stat.S_IMODE(folder.stat().st_mode) == 0o700
    command = [python, "-c", INTRUDER, address, str(scripts / "compute.py")]
    first = subprocess.run(command, user=65534, capture_output=True, text=True, timeout=120)
    assert first.stdout.strip() == "no entry", first.stderr
    os.chmod(folder, 0o711)
    os.chmod(address, 0o777)
    second = subprocess.run(command, user=65534, capture_output=True, text=True, timeout=120)
    assert second.stdout.strip() == "refused", second.stderr
    ready, _, _ = select.select([process.stdout], [], [], 120)
    assert ready and "refused: pid" in process.stdout.readline()
    assert not (tmp_path / "work" / "out" / "table.csv").exists()


def _python_for(uid: int) -> str:
    """An interpreter that ``uid`` may run (this one may sit in root's home)."""
    for python in (sys.executable, "/usr/bin/python3", "/usr/local/bin/python3"):
        try:
            subprocess.run([python, "-c", "pass"], user=uid, check=True, timeout=120)
            return python
        except (OSError, subprocess.CalledProcessError):
            continue
    pytest.skip(f"no Python interpreter that uid {uid} may run: not checked here")
