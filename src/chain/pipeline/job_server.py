"""The job server: a local run's jobs run where their imports are already paid
(``docs/job_server.md``).

A local run starts one server (:func:`start`, while Snakemake builds the DAG;
:func:`publish` in ``onstart``) that imports what the workflow's scripts import and
serves jobs on a Unix socket: each job's own process (the *client*, :func:`hand_off`)
hands its script over, and the server forks a child that runs it with the client's
directory, environment, streams and ``sys.path``. The client passes SIGINT and SIGTERM
on and exits with the child's status; a child whose client dies is stopped, and the
server exits with its Snakemake (``PR_SET_PDEATHSIG``).

Only its owner can hand it a job: the socket sits in a folder only the owner may enter
(0700), each peer's uid is checked (``SO_PEERCRED``) before a byte is read, and requests
are JSON, never pickle. A job whose interpreter, ``sys.prefix`` or root file system (a
container) is not the server's runs in its own process, as with no server at all.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from chain.pipeline.job_script import SIGNAL_BASE, run_script, signals_once

#: Environment variable: the server's socket (set by :func:`publish` for the jobs), or
#: ``off`` to run every job in its own process.
ADDRESS_VARIABLE = "HERTZCHAIN_JOB_SERVER"

#: Set in the server's children: a job already in the server runs where it is.
_IN_SERVER = False

#: The server's log (a copy of its stdout, which a child replaces with its job's).
_SERVER_LOG = 1

_HEADER = struct.Struct("!Q")  # length of the JSON request
_REQUEST_TIMEOUT = 10.0  # s: a client sends its request as soon as it has connected
_STATUS = struct.Struct("!q")  # the child's pid, then its exit status


# ---- the client: a job's own process --------------------------------------------------


def run(script: str) -> int:
    """Run a job's ``script`` (Snakemake's copy, with its preamble) in the job server
    if one is up and takes it, else in this process; its exit status."""
    status = hand_off(script)
    return run_script(script) if status is None else status


def in_server() -> bool:
    """Whether this process is a job the server runs (the client reuses and stores)."""
    return _IN_SERVER


def identity() -> dict:
    """What a job must share with the server to run in it: interpreter, prefix and
    root file system (a container's differs)."""
    root = os.stat("/")
    return {"executable": sys.executable, "prefix": sys.prefix, "root": [root.st_dev, root.st_ino]}


def hand_off(script: str) -> int | None:
    """Run ``script`` in the job server and return its exit status; None if no server
    is up or it does not take the job (another environment): run it here.

    Parameters
    ----------
    script : str
        The job's script: Snakemake's copy, with its preamble (``__real_file__``).
    """
    address = os.environ.get(ADDRESS_VARIABLE, "off")
    if _IN_SERVER or address == "off":
        return None
    try:
        connection = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        connection.connect(address)
        request = json.dumps(
            {
                "script": script,
                "cwd": os.getcwd(),
                "env": dict(os.environ),
                "path": sys.path,
                "identity": identity(),
                "sent": time.time(),  # for the server's log: how long the job waited
            }
        ).encode()
        socket.send_fds(connection, [_HEADER.pack(len(request))], [0, 1, 2])
        connection.sendall(request)
        child = _receive(connection)
    except OSError:
        return None  # no server (not up, gone): the job runs here
    if child is None:
        return None  # not taken (another environment), or the server went away
    return _wait_for(connection, child)


def _wait_for(connection: socket.socket, child: int) -> int:
    """The exit status of the server's ``child``; SIGINT and SIGTERM sent to this
    process are passed on to it (it takes the first and ignores repeats, so a signal
    sent to the whole process group, which reaches it directly too, acts once)."""

    def pass_on(signum, frame):
        with contextlib.suppress(ProcessLookupError):
            os.kill(child, signum)

    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, pass_on)
    status = _receive(connection)
    # No status: the child died without reporting (SIGKILL); a job that fails.
    return SIGNAL_BASE + signal.SIGKILL if status is None else status


def _receive(connection: socket.socket) -> int | None:
    """One integer from the other end, or None if it closed first."""
    data = b""
    while len(data) < _STATUS.size:
        try:
            chunk = connection.recv(_STATUS.size - len(data))
        except InterruptedError:  # pragma: no cover (PEP 475 retries)
            continue
        if not chunk:
            return None
        data += chunk
    return _STATUS.unpack(data)[0]


# ---- the server -----------------------------------------------------------------------


@dataclass(frozen=True)
class Server:
    """A job server that :func:`start` started: its process and its address."""

    process: subprocess.Popen
    address: str  # its socket, in a folder of its own (0700)


def start(scripts: str | os.PathLike, log: str | os.PathLike) -> Server | None:
    """Start a job server for the jobs of this process (a local Snakemake run); it
    serves them once :func:`publish` has told them where it is.

    Parameters
    ----------
    scripts : path
        The workflow's scripts folder: the server imports what they import.
    log : path
        The server's own log (its imports, the jobs it started).

    Returns
    -------
    Server or None
        The server; None if ``HERTZCHAIN_JOB_SERVER=off`` or not on Linux (the jobs run
        in their own processes).
    """
    if os.environ.get(ADDRESS_VARIABLE) == "off" or not sys.platform.startswith("linux"):
        return None
    # mkdtemp's folder is 0700: no other user can reach the socket (a short path:
    # a socket's is limited to 107 bytes).
    runtime = os.environ.get("XDG_RUNTIME_DIR")
    folder = tempfile.mkdtemp(prefix="hertzchain-", dir=runtime if runtime else None)
    address = os.path.join(folder, "socket")
    Path(log).parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as stream:
        process = subprocess.Popen(
            [sys.executable, "-m", "chain.pipeline.job_server", address, str(scripts)],
            stdin=subprocess.DEVNULL,
            stdout=stream,
            stderr=subprocess.STDOUT,
        )
    return Server(process, address)


def publish(server: Server | None) -> None:
    """Hand this process's jobs to ``server`` from now on: its address goes in the
    environment they inherit (:data:`ADDRESS_VARIABLE`). None: nothing to do.

    Parameters
    ----------
    server : Server or None
        What :func:`start` returned.
    """
    if server is not None:
        os.environ[ADDRESS_VARIABLE] = server.address


def stop(server: Server | None) -> None:
    """Stop a server :func:`start` started (None: nothing to do), take its address back
    from the jobs and remove its folder; its running children finish their jobs.

    Parameters
    ----------
    server : Server or None
        What :func:`start` returned.
    """
    if server is None:
        return
    if os.environ.get(ADDRESS_VARIABLE) == server.address:
        del os.environ[ADDRESS_VARIABLE]
    if server.process.poll() is None:
        server.process.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            server.process.wait(timeout=10)
    shutil.rmtree(Path(server.address).parent, ignore_errors=True)


def serve(address: str, scripts: Path) -> None:
    """The server's main loop: listen at ``address``, fork a child per job until the
    parent (Snakemake) is gone or a SIGTERM or SIGINT arrives (then it exits at once),
    and between jobs import what the ``scripts`` import, one module at a time (a job
    that comes first is forked with what is imported so far). Before each job, load
    what the library it runs defers (imports in functions, numba's cached kernels:
    :mod:`chain.pipeline.preload`).

    Parameters
    ----------
    address : str
        The socket's path, in a folder only its owner may enter (:func:`start`).
    scripts : Path
        The workflow's scripts folder.
    """
    from chain.pipeline.preload import load_deferred_imports_for, load_kernels_for, preload_steps

    global _SERVER_LOG
    _SERVER_LOG = os.dup(1)
    parent = os.getppid()
    _die_with_parent()
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(address)
    listener.listen(64)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda signum, frame: os._exit(0))
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # children reap themselves
    steps = preload_steps(scripts, address)
    preloading = True
    while os.getppid() == parent:
        listener.settimeout(0.0 if preloading else 1.0)  # no wait while there is preloading
        try:
            connection, _ = listener.accept()
        except (TimeoutError, BlockingIOError):
            if preloading and (step := next(steps, None)):
                step()
            else:
                preloading = False
            continue
        try:
            _check_peer(connection)
            connection.settimeout(_REQUEST_TIMEOUT)
            request, fds = _read_request(connection)
            connection.settimeout(None)
        except Exception as refused:  # no pid: a client of ours runs the job itself
            if isinstance(refused, PermissionError):
                print(f"job server: refused: {refused}", flush=True)
            connection.close()
            continue
        load_deferred_imports_for(request["script"])
        load_kernels_for(request["script"])
        if os.fork() == 0:
            listener.close()
            _run_child(connection, request, fds)  # never returns
        for fd in fds:
            os.close(fd)
        connection.close()


def _die_with_parent() -> None:
    """Have the kernel send this process SIGTERM when its parent exits (Linux)."""
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG


# ---- a child: one job -------------------------------------------------------------------


def _run_child(connection: socket.socket, request: dict, fds: list[int]) -> None:
    """Become the job that sent ``request`` and ``fds`` (:func:`_read_request`), run
    its script, report its exit status and exit. A child that fails before it sent its
    pid closes without a word: the client then runs the job itself."""
    global _IN_SERVER
    _IN_SERVER = True
    signals_once()
    started, status = False, 1
    try:
        _adopt(request, fds)
        connection.sendall(_STATUS.pack(os.getpid()))
        started = True
        _stop_when_client_dies(connection)
        waited = time.time() - request.get("sent", time.time())
        begun = time.perf_counter()
        status = run_script(request["script"])
        took = time.perf_counter() - begun
        _log(
            f"{Path(request['script']).name}: status {status}, {took:.2f} s, "
            f"forked {waited:.2f} s after its request"
        )
    finally:
        # Nothing may interrupt the way out (the watcher's SIGTERM once the client has
        # its status): this process must end here, not unwind into the server's loop.
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        if started:
            with contextlib.suppress(OSError):
                connection.sendall(_STATUS.pack(status))
        os._exit(status)


def _log(line: str) -> None:
    """A line in the server's log, from a child (whose stdout is its job's)."""
    with contextlib.suppress(OSError):
        os.write(_SERVER_LOG, f"job server: pid {os.getpid()}: {line}\n".encode())


def _check_peer(connection: socket.socket) -> None:
    """Raise PermissionError unless the peer runs as this server's user (its uid, read
    by the kernel at connect time)."""
    credentials = struct.Struct("3i")
    pid, uid, _ = credentials.unpack(
        connection.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED, credentials.size)
    )
    if uid != os.getuid():
        raise PermissionError(f"pid {pid} runs as uid {uid}, not as uid {os.getuid()}")


def _read_request(connection: socket.socket) -> tuple[dict, list[int]]:
    """A client's request (script, directory, environment, import path) and its
    streams' file descriptors (stdin, stdout, stderr)."""
    header, fds, _, _ = socket.recv_fds(connection, _HEADER.size, 3)
    try:
        if len(header) != _HEADER.size or len(fds) != 3:
            raise ConnectionError("the client closed before its request was read")
        (length,) = _HEADER.unpack(header)
        data = b""
        while len(data) < length:
            chunk = connection.recv(length - len(data))
            if not chunk:
                raise ConnectionError("the client closed before its request was read")
            data += chunk
        request = json.loads(data)
        if request.get("identity") != identity():
            raise ConnectionRefusedError("another environment: the job runs in its own")
        return request, fds
    except BaseException:
        for fd in fds:
            os.close(fd)
        raise


def _adopt(request: dict, fds: list[int]) -> None:
    """Take the client's streams, directory, environment and import path."""
    import tempfile

    for target, fd in enumerate(fds):
        os.dup2(fd, target)
        os.close(fd)
    sys.stdin = open(0, closefd=False)
    sys.stdout = open(1, "w", closefd=False)
    sys.stderr = open(2, "w", closefd=False)
    os.chdir(request["cwd"])
    os.environ.clear()
    os.environ.update(request["env"])
    os.environ[ADDRESS_VARIABLE] = "off"  # the job's own subprocesses run where they are
    tempfile.tempdir = None  # TMPDIR is the job's (a resource of the rule)
    sys.path[:] = request["path"]
    signal.signal(signal.SIGCHLD, signal.SIG_DFL)  # the job's own children are waited for


def _stop_when_client_dies(connection: socket.socket) -> None:
    """SIGTERM this child if its client goes away (killed): the job is over for
    Snakemake, and the atomic writers clean up on SystemExit."""
    import threading

    def watch():
        with contextlib.suppress(OSError):
            connection.recv(1)  # the client sends nothing more: returns at its end
        os.kill(os.getpid(), signal.SIGTERM)

    threading.Thread(target=watch, daemon=True).start()


if __name__ == "__main__":
    # Through the package's module, not this __main__ copy of it: the children's
    # hand_off must see _IN_SERVER set (else each job would hand itself off again).
    from chain.pipeline import job_server

    job_server.serve(sys.argv[1], Path(sys.argv[2]))
