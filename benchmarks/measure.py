"""Measurement discipline shared by the benchmarks.

The machines the benchmarks run on are shared and noisy, so every speed figure is:

* the **best of at least** :data:`MIN_REPEAT` **interleaved runs** (each round runs every
  contender once, so that load hits all of them alike; the best run is the one the
  other jobs disturbed least);
* printed with the **load average before and after** and the **C build flags** of the
  yardstick;
* judged against its target only when the machine was quiet: a figure taken while
  the 1-minute load average exceeded the number of cores is printed as
  :data:`UNDER_LOAD` and never as met.

Every benchmark writes what it measured to ``benchmarks/results/<benchmark>.json``
(:func:`write_result`: its figures with the machine, the load and the commit), and
with it the table of ``benchmarks/README.md``, regenerated from all those files
(:func:`write_table`; ``python benchmarks/table.py`` does only that).

Not a test: nothing here asserts.
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib.metadata
import json
import math
import os
import platform
import shlex
import shutil
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
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


def cpu_model() -> str:
    """The CPU's model name, read from /proc/cpuinfo where there is one."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine() -> str:
    """CPU model and core count, read from /proc/cpuinfo where there is one."""
    return f"{cpu_model()}, nproc {os.cpu_count()}"


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
    labels: list = field(default_factory=list)

    def sample(self, label: str) -> float:
        """Read and print the load average now (``label``: "before", "after")."""
        load = load_average()
        self.loads.append(load)
        self.labels.append(label)
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


_TICK_S = 1.0 / os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 0.01


def _steal_seconds() -> float:
    """Time the hypervisor gave this machine's CPUs to other machines since boot, s
    (/proc/stat; NaN where there is none)."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()
        return int(fields[8]) * _TICK_S
    except (OSError, IndexError, ValueError):
        return math.nan


def _processes() -> dict[int, tuple[int, float, float]]:
    """Every process now: pid -> (parent pid, CPU time used (user + system) s, start
    time s after boot), from /proc/<pid>/stat."""
    table = {}
    for entry in os.scandir("/proc"):
        if not entry.name.isdigit():
            continue
        try:
            text = Path(entry.path, "stat").read_text()
        except OSError:  # gone since the listing
            continue
        fields = text[text.rindex(")") + 2 :].split()  # after "pid (comm) "
        cpu = (int(fields[11]) + int(fields[12])) * _TICK_S
        table[int(entry.name)] = (int(fields[1]), cpu, int(fields[19]) * _TICK_S)
    return table


def _descends_from(pid: int, root: int, table: dict) -> bool:
    seen = set()
    while pid not in seen and pid > 1:
        if pid == root:
            return True
        seen.add(pid)
        pid = table.get(pid, (0,))[0]
    return False


@dataclass
class OtherProcesses:
    """The CPU other processes took while a command ran, to judge whether the command's
    time measured it: a whole workflow loads every core itself, so the load average
    after it says nothing of other users. Use as ``with OtherProcesses() as other:``
    around a command that this process starts; then ``other.share`` is the fraction of
    the machine's CPU (``cores`` x wall) that processes not descended from this one
    used, steal time included, and ``other.quiet`` whether it stayed below
    :data:`MAX_OTHER_SHARE`. The processes are read every ``interval`` s (/proc): a
    process of another user is counted from when it started or the measurement did;
    what one used in its last ``interval`` before it exited is missed, and so is a
    process of ours whose parent exited before it was seen (it counts as another's:
    the judgement errs towards "loaded"). Where there is no /proc, ``share`` is NaN and
    nothing is quiet."""

    cores: int = field(default_factory=lambda: os.cpu_count() or 1)
    interval: float = 0.5
    share: float = math.nan

    def __enter__(self):
        self._wall0, self._steal0 = time.perf_counter(), _steal_seconds()
        self._boot_s = time.clock_gettime(time.CLOCK_BOOTTIME)
        self._first, self._last = {}, {}  # another's pid -> CPU s when first, last seen
        self._sample(at_start=True)
        self._done = threading.Event()
        self._thread = threading.Thread(target=self._watch, daemon=True)
        self._thread.start()
        return self

    def _watch(self) -> None:
        while not self._done.wait(self.interval):
            self._sample()

    def _sample(self, at_start: bool = False) -> None:
        try:
            table = _processes()
        except OSError:
            return
        me = os.getpid()
        for pid, (_, cpu, started) in table.items():
            if pid in self._first:
                self._last[pid] = cpu
            elif not _descends_from(pid, me, table):
                # Started before the measurement: count from now; after: all of it.
                self._first[pid] = cpu if at_start or started < self._boot_s else 0.0
                self._last[pid] = cpu

    def __exit__(self, *exc) -> None:
        self._done.set()
        self._thread.join()
        self._sample()
        used = sum(self._last[pid] - self._first[pid] for pid in self._first)
        used += _steal_seconds() - self._steal0
        self.share = max(used, 0.0) / (self.cores * (time.perf_counter() - self._wall0))

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


# Results files: what a benchmark measured, where and when.

ROOT = Path(__file__).resolve().parents[1]
RESULTS = Path(__file__).parent / "results"
#: Keys of every results file, and of each of its figures.
RESULT_KEYS = (
    "benchmark",
    "command",
    "date_utc",
    "commit",
    "dirty",
    "machine",
    "load_average",
    "others_cpu_share",
    "loaded",
    "figures",
)
FIGURE_KEYS = ("name", "value", "unit", "ratio_to", "target", "verdict", "bounded_by")
#: Units of figures that the load does not change (peak memory, a count of jobs): judged
#: as measured.
LOAD_INDEPENDENT_UNITS = ("MB", "jobs")


@dataclass(frozen=True)
class Figure:
    """One figure a benchmark measured: ``value`` in ``unit``.

    ``ratio_to`` names the yardstick, measured in the same run, that ``value`` is a ratio
    to (None: an absolute figure); ``target`` the bound it is judged against ("": none)
    and ``verdict`` the judgement ("met", "not met", :data:`UNDER_LOAD`, or ""); and
    ``bounded_by`` says in one line what sets the figure (what the work costs at best).
    """

    name: str
    value: float | None
    unit: str
    bounded_by: str
    ratio_to: str | None = None
    target: str = ""
    verdict: str = ""


def _git(*args: str) -> str | None:
    try:
        done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
    except OSError:
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def commit() -> tuple[str | None, bool | None]:
    """The checkout's commit (short hash) and whether its files differ from it (the
    results files and the benchmarks' README excepted: they change nothing measured)."""
    status = _git(
        "status",
        "--porcelain",
        "--",
        ".",
        ":(exclude)benchmarks/results",
        ":(exclude)benchmarks/README.md",
    )
    return _git("rev-parse", "--short", "HEAD"), None if status is None else bool(status)


def machine_info() -> dict:
    """The machine and the versions a figure depends on."""

    def version(package: str) -> str | None:
        try:
            return importlib.metadata.version(package)
        except importlib.metadata.PackageNotFoundError:
            return None

    return {
        "cpu": cpu_model(),
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": version("numba"),
    }


def command_line() -> str:
    """The command that runs this benchmark, as typed from the repository's root."""
    script = Path(sys.argv[0]).resolve()
    if script.is_relative_to(ROOT):
        script = script.relative_to(ROOT)
    return shlex.join(["python", str(script), *sys.argv[1:]])


def _finite(value):
    return None if value is None or not math.isfinite(value) else value


def _loads(conditions: Conditions) -> dict:
    """The first and last load average read, and every reading when there were more."""
    loads = [_finite(round(load, 2)) for load in conditions.loads] or [None]
    readings = {"cores": conditions.cores, "before": loads[0], "after": loads[-1]}
    if conditions.labels not in ([], ["before", "after"]):
        readings["readings"] = dict(zip(conditions.labels, loads, strict=True))
    return readings


def write_result(
    benchmark: str,
    figures: list[Figure],
    conditions: Conditions,
    others: float | None = None,
    *,
    own_load: bool = False,
    folder: Path | None = None,
    readme: Path | None = None,
) -> Path:
    """Write ``folder/<benchmark>.json``: the ``figures``, the command line, the date
    (UTC), the commit (and whether the checkout differed from it), the machine, the load
    averages that ``conditions`` read and ``others``, the share of the machine's CPU that
    other processes took meanwhile (:class:`OtherProcesses`; None: not measured). Then
    regenerate the table of ``readme`` from every results file of ``folder``
    (:func:`write_table`), so that a benchmark's run leaves the two in agreement.

    ``folder`` is :data:`RESULTS` by default, and ``readme`` then :data:`README`; another
    folder's results go in no README unless one is given.

    The run is ``loaded`` when others took more than :data:`MAX_OTHER_SHARE` or (unless
    ``own_load``: the benchmark loads every core itself, as a workflow does) a load
    average exceeded the cores; then no figure is "met" (its verdict becomes
    :data:`UNDER_LOAD`), except a peak memory (:data:`LOAD_INDEPENDENT_UNITS`)."""
    loaded = not (others is None or others <= MAX_OTHER_SHARE)
    loaded = loaded or (conditions.under_load and not own_load)
    rows = []
    for figure in figures:
        row = {key: getattr(figure, key) for key in FIGURE_KEYS}
        row["value"] = _finite(figure.value)
        if isinstance(row["value"], float):
            row["value"] = float(f"{row['value']:.4g}")
        if loaded and figure.verdict == "met" and figure.unit not in LOAD_INDEPENDENT_UNITS:
            row["verdict"] = UNDER_LOAD
        rows.append(row)
    head, dirty = commit()
    result = {
        "benchmark": benchmark,
        "command": command_line(),
        "date_utc": datetime.now(UTC).strftime("%Y-%m-%dT%H:%MZ"),
        "commit": head,
        "dirty": dirty,
        "machine": machine_info(),
        "load_average": _loads(conditions),
        "others_cpu_share": None if others is None else _finite(round(others, 4)),
        "loaded": loaded,
        "figures": rows,
    }
    if folder is None:
        folder, readme = RESULTS, README if readme is None else readme
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{benchmark}.json"
    with _one_writer(folder):  # another benchmark's table then has this file
        _write_atomically(path, json.dumps(result, indent=1, ensure_ascii=False) + "\n")
        print(f"results: {_shown(path)}")
        if readme is not None:
            changed = write_table(readme, folder)
            print(f"{_shown(readme)}: table {'rewritten' if changed else 'unchanged'}")
    return path


def read_results(folder: Path = RESULTS) -> list[dict]:
    """Every results file of ``folder``, by benchmark name."""
    return [json.loads(p.read_text(encoding="utf-8")) for p in sorted(folder.glob("*.json"))]


def _shown(path: Path) -> Path:
    return path.relative_to(ROOT) if path.is_relative_to(ROOT) else path


@contextlib.contextmanager
def _one_writer(folder: Path):
    """One benchmark at a time writes its results file and the table (POSIX ``flock``
    on ``folder/.lock``; nothing where there is no fcntl)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    with (folder / ".lock").open("a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _write_atomically(path: Path, text: str) -> None:
    """``text`` to ``path`` through a temporary file beside it: a reader (another
    benchmark regenerating the table) never sees half a file."""
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        temporary.write_text(text, encoding="utf-8")
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)


# The table of benchmarks/README.md, generated from the results files: by write_result
# after each benchmark's run, or by ``python benchmarks/table.py``.

README = Path(__file__).parent / "README.md"
TABLE_BEGIN = "<!-- results: generated by `python benchmarks/table.py`; do not edit -->"
TABLE_END = "<!-- end of the results -->"


def _number(value) -> str:
    if value is None:
        return "n/a"
    if abs(value) >= 1000:
        return f"{value:,.0f}"
    text = f"{value:.3g}"
    if value != round(value) and float(text) == round(value):  # 1.002 is not "1"
        text = f"{value:.2f}"
    return text


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _row(cells) -> str:
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


def table(results: list[dict]) -> str:
    """The tables of ``benchmarks/README.md``: every figure, then where and when each
    benchmark measured them."""
    lines = [
        _row(("benchmark", "figure", "value", "ratio to", "target", "verdict", "bounded by")),
        _row(("---",) * 7),
    ]
    for result in results:
        for figure in result["figures"]:
            value = f"{_number(figure['value'])} {figure['unit']}".strip()
            lines.append(
                _row(
                    (
                        result["benchmark"],
                        figure["name"],
                        value,
                        figure["ratio_to"] or "",
                        figure["target"],
                        figure["verdict"],
                        figure["bounded_by"],
                    )
                )
            )
    lines += [
        "",
        _row(
            (
                "benchmark",
                "command",
                "date (UTC)",
                "commit",
                "machine",
                "load average",
                "others' CPU",
            )
        ),
        _row(("---",) * 7),
    ]
    for result in results:
        machine, load = result["machine"], result["load_average"]
        loads = f"{_number(load['before'])} -> {_number(load['after'])} on {load['cores']} cores"
        share = result["others_cpu_share"]
        lines.append(
            _row(
                (
                    result["benchmark"],
                    f"`{result['command']}`",
                    result["date_utc"],
                    (result["commit"] or "?") + (" (modified)" if result["dirty"] else ""),
                    f"{machine['cpu']}, {machine['cores']} cores; Python {machine['python']}, "
                    f"numpy {machine['numpy']}, numba {machine['numba']}",
                    loads + (" (loaded)" if result["loaded"] else ""),
                    "not measured" if share is None else f"{share:.1%}",
                )
            )
        )
    return "\n".join(lines)


def readme_table(text: str) -> str:
    """The generated part of a README's ``text``, between the markers."""
    start, end = text.index(TABLE_BEGIN) + len(TABLE_BEGIN), text.index(TABLE_END)
    return text[start:end].strip("\n")


def write_table(readme: Path = README, folder: Path = RESULTS) -> bool:
    """Write the table of ``folder``'s results into ``readme``; True when it changed."""
    text = readme.read_text(encoding="utf-8")
    start, end = text.index(TABLE_BEGIN) + len(TABLE_BEGIN), text.index(TABLE_END)
    new = text[:start] + "\n" + table(read_results(folder)) + "\n" + text[end:]
    if new != text:
        _write_atomically(readme, new)
    return new != text
