"""Measurement discipline shared by the benchmarks (issue 25, item 4).

The machines the benchmarks run on are shared and noisy, so every speed figure is:

* the **best of at least** :data:`MIN_REPEAT` **interleaved runs** (each round runs every
  contender once, so that load hits all of them alike; the best run is the one the
  other jobs disturbed least);
* printed with the **load average before and after** and the **C build flags** of the
  yardstick;
* judged against its target only when the machine was quiet: a figure taken while
  the 1-minute load average exceeded the number of cores is printed as
  :data:`UNDER_LOAD` and never as met.

Not a test: nothing here asserts.
"""

from __future__ import annotations

import ctypes
import math
import os
import platform
import shutil
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Fewest interleaved rounds behind a speed figure.
MIN_REPEAT = 7
#: How the C yardstick is built (besides -shared -fPIC and -lm).
C_FLAGS = ("-O3", "-march=native")
C_SOURCE = Path(__file__).parent / "c" / "rk4_chain.c"
#: The verdict of a figure measured on a loaded machine.
UNDER_LOAD = "UNDER LOAD — not a measurement of the target"
_DOUBLE_P = ctypes.POINTER(ctypes.c_double)


def machine() -> str:
    """CPU model and core count, read from /proc/cpuinfo where there is one."""
    model = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{model}, nproc {os.cpu_count()}"


def load_average() -> float:
    """The 1-minute load average (NaN where the system has none)."""
    try:
        return os.getloadavg()[0]
    except OSError:
        return math.nan


def peak_memory_mb() -> float:
    """This process's peak resident memory since it started its program, MB.

    ``VmHWM`` of /proc/self/status where there is one: ``ru_maxrss`` also counts the
    memory of the parent that forked the process, up to its exec (Linux folds the
    forked copy's high-water mark into it), so a child started by a large benchmark
    read the parent's size (measured: 331-349 MB against the child's own 249 MB)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


@dataclass
class Conditions:
    """Load averages seen around a measurement, to judge whether it measured anything."""

    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    loads: list = field(default_factory=list)

    def sample(self, label: str) -> float:
        """Read and print the load average now (``label``: "before", "after")."""
        load = load_average()
        self.loads.append(load)
        print(f"load average {label}: {load:.2f} on {self.cores} cores")
        return load

    @property
    def under_load(self) -> bool:
        """True when any reading exceeded the number of cores (or none was possible)."""
        return not self.loads or any(not load <= self.cores for load in self.loads)

    def verdict(self, met: bool) -> str:
        """ "met" / "not met", or :data:`UNDER_LOAD` whatever the figure."""
        if self.under_load:
            return UNDER_LOAD
        return "met" if met else "not met"


#: Most of the machine's CPU that other processes may use during a measured command
#: for it to count as a measurement (:class:`OtherProcesses`).
MAX_OTHER_SHARE = 0.05


def _machine_cpu_seconds() -> tuple[float, float]:
    """CPU time every process of the machine used since boot (user, nice, system, irq,
    softirq) and the time the hypervisor gave this machine's CPUs to others (steal),
    s, from /proc/stat; NaN where there is none."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()[1:]
    except (OSError, IndexError):
        return math.nan, math.nan
    ticks = [int(value) for value in fields] + [0] * 8
    user, nice, system, _, _, irq, softirq, steal = ticks[:8]
    per_second = os.sysconf("SC_CLK_TCK")
    return (user + nice + system + irq + softirq) / per_second, steal / per_second


def _own_cpu_seconds() -> float:
    """CPU time of this process and of every child it (or a child of a child) waited
    for, s."""
    times = os.times()
    return times.user + times.system + times.children_user + times.children_system


@dataclass
class OtherProcesses:
    """The CPU other processes took while a command ran, to judge whether the command's
    time measured it: a whole workflow loads every core itself, so the load average
    after it says nothing of other users. Use as ``with OtherProcesses() as other:``
    around a command whose processes this one waits for; then ``other.share`` is the
    fraction of the machine's CPU (``cores`` x wall) the rest of the machine used,
    steal time included, and ``other.quiet`` whether it stayed below
    :data:`MAX_OTHER_SHARE`. A process of the command that nobody waited for counts
    as another's: the judgement errs towards "loaded"."""

    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    share: float = math.nan

    def __enter__(self):
        self._start = (time.perf_counter(), _own_cpu_seconds(), *_machine_cpu_seconds())
        return self

    def __exit__(self, *exc) -> None:
        wall0, own0, busy0, steal0 = self._start
        busy1, steal1 = _machine_cpu_seconds()
        others = (busy1 - busy0) - (_own_cpu_seconds() - own0) + (steal1 - steal0)
        self.share = max(others, 0.0) / (self.cores * (time.perf_counter() - wall0))

    @property
    def quiet(self) -> bool:
        return self.share <= MAX_OTHER_SHARE


def check_repeat(repeat: int) -> int:
    """``repeat``, refused below :data:`MIN_REPEAT`."""
    if repeat < MIN_REPEAT:
        raise SystemExit(f"--repeat must be >= {MIN_REPEAT} (best of >= {MIN_REPEAT} runs)")
    return repeat


def best_times(contenders: dict, repeat: int, clock=time.thread_time, clocks=None) -> dict:
    """Best time (s) of each callable over ``repeat`` interleaved rounds.

    The calling thread's CPU time by default: a call that runs on this thread (one
    launch of our kernel, the C yardstick) is then charged neither for the time other
    jobs held the core nor for other threads of this process. process_time was used
    before and charged the idle spin of numba's parallel workers (the reference
    kernel's prange region) to whatever call came next: about 3 ms, which made
    ``simulate / C`` read 1.5-1.9 for a call costing 1.1 x C. Pass ``time.perf_counter``
    (wall time, quiet machine) for calls that use several threads, as ``clock`` or per
    name in ``clocks``."""
    clocks = {name: (clocks or {}).get(name, clock) for name in contenders}
    best = dict.fromkeys(contenders, math.inf)
    for _ in range(check_repeat(repeat)):
        for name, function in contenders.items():
            start = clocks[name]()
            function()
            best[name] = min(best[name], clocks[name]() - start)
    return best


def load_c(folder: str):
    """The C yardstick built with :data:`C_FLAGS`: (function, command), or (None, why)."""
    compiler = shutil.which("cc")
    if compiler is None:
        return None, "no C compiler (cc) on PATH"
    library = Path(folder) / "rk4_chain.so"
    command = [compiler, *C_FLAGS, "-shared", "-fPIC", str(C_SOURCE), "-o", str(library), "-lm"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        return None, f"cc failed: {done.stderr.strip()}"
    function = ctypes.CDLL(str(library)).rk4_chain
    function.restype = ctypes.c_int
    function.argtypes = [ctypes.c_int] + [ctypes.c_double] * 4 + [ctypes.c_long] * 2
    function.argtypes += [_DOUBLE_P] * 4
    return function, " ".join(command)


def c_run(function, velocity, mass, kappa, eta, dt, n_steps, record_every):
    """One C run of the launch ``velocity`` (m/s per bead) of equal beads of ``mass``
    (kg), contact stiffness ``kappa`` and Kuwabara-Kono time ``eta`` (s); returns
    (contact forces (S, N-1) N, E_kin + E_pot (S,) J)."""
    n = len(velocity)
    u, v = np.zeros(n), np.array(velocity, dtype=float)
    force = np.zeros((n_steps // record_every + 1, n - 1))
    energy = np.zeros(n_steps // record_every + 1)
    pointers = [a.ctypes.data_as(_DOUBLE_P) for a in (u, v, force, energy)]
    function(n, mass, kappa, 1.5 * eta * kappa, dt, n_steps, record_every, *pointers)
    return force, energy
