"""Shared fixtures and named tolerances for the physics tests of the simulation core,
and how the suite runs in parallel.

Every tolerance a physics test asserts against lives here, with the reason for its
size, so that a reader sees at once how tight each check is. Tests reach them through
the ``tol`` fixture (no ``import conftest``: robust to pytest's import modes).

The suite runs on every core (pytest-xdist, ``-n auto``) unless told otherwise; see
:func:`pytest_cmdline_main`. A test file needs nothing for that. A workflow run that
several tests inspect is built once per session, whichever worker asks first, with
:func:`built_once` (a module-scoped fixture would be built once per worker); a test
that changes it works on a copy.
"""

from __future__ import annotations

import contextlib
import math
import os
import shutil
import subprocess
import sys
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from chain import STEEL_100C6, contact_stiffness, sphere_mass

#: The paper's beads: 100C6 steel spheres of radius 13 mm (Sec. III).
PAPER_RADIUS = 13e-3

#: The paper's Kuwabara-Kono relaxation time, s (Sec. II).
PAPER_ETA = 0.58e-6


@dataclass(frozen=True)
class Tolerances:
    """Named tolerances of the physics suite (relative unless the name says otherwise)."""

    #: Relative drift of E_kin + E_pot + E_diss with the default step (the paper's 1e-9).
    energy_drift: float = 1e-9
    #: Total momentum with free ends, relative to m V0: round-off only (forces are
    #: internal and pairwise opposite in every stage of RK4).
    momentum: float = 1e-12
    #: Two-sphere contact time and peak force against the exact Hertz closed forms,
    #: with 2000 steps per contact time (measured ~3e-10; the brief asks 1e-6 or better).
    hertz_collision: float = 1e-8
    #: Velocity exchange of two equal elastic spheres, relative to the impact speed.
    velocity_exchange: float = 1e-9
    #: Solitary-wave speed against Eq. 5 with the measured F_m (Eq. 5 is the
    #: long-wavelength approximation; the discrete wave is ~1.2 % faster).
    solitary_speed: float = 0.02
    #: Integral width of the solitary wave against pi sqrt(10) R / (2R) = 4.97 beads
    #: (the discrete wave is ~3.5 % narrower than the cos^6 hump).
    solitary_width: float = 0.05
    #: Exact scaling symmetry F ~ V0^(6/5), t ~ V0^(-1/5) with dt scaled the same way:
    #: the two runs are the same run in scaled units, equal up to round-off (~1e-12).
    scaling: float = 1e-9
    #: numba RK4 against scipy DOP853 (rtol 1e-12), relative to the peak force
    #: (measured ~3e-8 with the default step).
    ivp_force: float = 1e-6
    #: Peak reading of a split sensor bead (PCB 200B02, 1.9e9 N/m) against the peak of
    #: (F_{n-1,n} + F_{n,n+1}) / 2 of an unsplit bead (measured 0.4 % low at 1 m/s).
    sensor_peak: float = 0.01
    #: Arrival (peak) time of the sensor reading against the unsplit bead's, as a
    #: fraction of the pulse's integral duration (measured <= 1.5 %).
    sensor_arrival_fraction: float = 0.02
    #: A bead bouncing off a rigid wall with eta = 0: speed restored, relative.
    wall_speed: float = 1e-9
    #: Kuwabara-Kono: 1 - e ~ V^(1/5) to leading order in eta; absolute tolerance on the
    #: fitted exponent over 0.01..1 m/s (measured 0.197).
    kk_exponent_abs: float = 0.01
    #: Eq. 6 as printed: 49.74 us N^(1/6), absolute, us N^(1/6).
    cbal_paper_abs_us: float = 0.02
    #: First line of Eq. 6 against the printed second line (prefactor 0.7612 has 4 digits).
    cbal_first_line: float = 1e-3
    #: Closed forms that are algebraically identical: round-off.
    roundoff: float = 1e-12
    #: Numerical quadrature (scipy.integrate.quad) of the Hertz time constant.
    quadrature: float = 1e-10
    #: CSV round trip: the trace format writes 10 significant digits.
    csv_round_trip: float = 1e-9


@pytest.fixture(scope="session")
def tol() -> Tolerances:
    """The named tolerances of the physics suite."""
    return Tolerances()


@pytest.fixture(scope="session")
def steel():
    """The paper's bead material (100C6 steel)."""
    return STEEL_100C6


@pytest.fixture(scope="session")
def radius() -> float:
    """The paper's bead radius, m."""
    return PAPER_RADIUS


@pytest.fixture(scope="session")
def eta() -> float:
    """The paper's Kuwabara-Kono relaxation time, s."""
    return PAPER_ETA


@pytest.fixture(scope="session")
def bead_mass(steel, radius) -> float:
    """Mass of one of the paper's beads, kg."""
    return sphere_mass(steel, radius)


@pytest.fixture(scope="session")
def kappa(steel, radius) -> float:
    """Hertz stiffness of a contact between two of the paper's beads, N/m^(3/2)."""
    return contact_stiffness(steel, radius, steel, radius)


@pytest.fixture(scope="session")
def wall_kappa(steel, radius) -> float:
    """Hertz stiffness of one of the paper's beads against a flat steel wall, N/m^(3/2)."""
    return contact_stiffness(steel, radius, steel, math.inf)


def parabolic_peak(time: np.ndarray, signal: np.ndarray) -> tuple[float, float]:
    """Time and value of the maximum of an evenly sampled ``signal``, refined by the
    parabola through the largest sample and its two neighbours."""
    j = int(np.argmax(signal))
    if not 0 < j < len(signal) - 1:
        raise AssertionError(f"peak at the edge of the record (sample {j}): record longer")
    a, b, c = signal[j - 1], signal[j], signal[j + 1]
    curvature = a - 2.0 * b + c
    offset = 0.5 * (a - c) / curvature if curvature != 0 else 0.0
    return time[j] + offset * (time[1] - time[0]), b - 0.25 * (a - c) * offset


def hertz_release_time(time: np.ndarray, force: np.ndarray) -> float:
    """Time at which a Hertz contact opens, from its recorded force.

    F^(2/3) = kappa^(2/3) delta is smooth (nearly linear) through the opening, so the
    zero crossing is extrapolated linearly from the last two samples with F > 0.
    """
    positive = np.flatnonzero(force > 0)
    if positive.size < 2 or positive[-1] == len(force) - 1:
        raise AssertionError("the contact does not open within the record")
    i = positive[-1]
    y = force ** (2.0 / 3.0)
    return time[i] + y[i] * (time[i] - time[i - 1]) / (y[i - 1] - y[i])


@pytest.fixture(scope="session")
def peak_of():
    """``peak_of(time, signal) -> (t_peak, value)``: parabolic refinement of the maximum."""
    return parabolic_peak


@pytest.fixture(scope="session")
def release_time():
    """``release_time(time, force) -> t``: interpolated opening time of a Hertz contact."""
    return hertz_release_time


# ---- the config schema, parsed once ----------------------------------------------------


@pytest.fixture(scope="session", autouse=True)
def schema_parsed_once() -> Iterator[None]:
    """snakemake.utils.validate, which the tests call as the Snakefile does, reads and
    parses its schema file at every call (YAML through yte: ~40 ms for the config
    schema), and the tests validate some 200 configs (~8 s of CPU a session). Here
    snakemake's loader parses each schema file once per process and gives validate a
    copy of it while the file is unchanged (path, size, modification time): every
    config is checked by the same code against the same schema. Only where a test
    module has imported snakemake.utils already (at collection), so that a session
    without them does not import Snakemake for this; loads other than a schema file's
    go through untouched."""
    import copy
    import sys

    utils = sys.modules.get("snakemake.utils")
    load = getattr(utils, "_load_configfile", None)
    if load is None:
        yield
        return
    parsed = {}

    def load_schema_once(source, filetype="Config"):
        if filetype != "Schema" or not isinstance(source, str | os.PathLike):
            return load(source, filetype=filetype)
        try:
            stat = Path(source).stat()
        except OSError:  # snakemake's own error
            return load(source, filetype=filetype)
        key = (str(Path(source).resolve()), stat.st_size, stat.st_mtime_ns)
        if key not in parsed:
            parsed[key] = load(source, filetype=filetype)
        return copy.deepcopy(parsed[key])

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(utils, "_load_configfile", load_schema_once)
        yield


# ---- the suite on every core (pytest-xdist) -------------------------------------------

#: The checkout (its Snakefile, workflow/ and src/).
ROOT = Path(__file__).resolve().parents[1]


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config: pytest.Config) -> None:
    """``python -m pytest`` runs one worker per core (pytest-xdist's ``-n auto``), each
    worker given one test at a time beyond its first two (``--maxschedchunk 1``), in
    the order of :func:`pytest_collection_modifyitems`: the long workflow tests first,
    spread over the workers as they come free.

    Set here, not in ``addopts``, so that ``-p no:xdist`` still parses (a plain serial
    run), and so that an explicit ``-n`` (``-n 0``: serial), ``--dist`` or
    ``--maxschedchunk`` wins, as does ``--pdb``, which needs one process. Runs before
    xdist's own hook (both tryfirst, a conftest registers later), which turns "auto"
    into a number.
    """
    if not config.pluginmanager.hasplugin("xdist") or hasattr(config, "workerinput"):
        return
    option = config.option
    if option.numprocesses is None and not (option.usepdb or option.collectonly):
        option.numprocesses = "auto"
    if getattr(option, "maxschedchunk", 0) is None:
        option.maxschedchunk = 1


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "heavy(cpu_s): a workflow test that runs Snakemake jobs again on a copy of a run "
        "built once, for about cpu_s seconds of CPU (measured): started as soon as that "
        "run is built, the longest first (tests/conftest.py)",
    )
    config.pluginmanager.register(_CompilingFirst(), "hertzchain-compiling-first")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Order the tests for the workers; a serial run sees the same order.

    xdist gives each worker two tests to start with, then one more as each ends. So the
    first test of each shared workflow run (:func:`built_once`) goes at positions 0, 2,
    4, ..., each followed by a short test: every worker starts by building a different
    run, rather than wait for another's, the run that most tests inspect first. Then
    the other tests marked ``workflow``: those that need no shared run (a worker runs
    them while the runs build), those marked ``heavy``, the longest first (the first of
    them waits for its run, which then has both cores), the others; then the rest,
    which fill the end (those that compile numba's kernels first, once the tests not
    selected are left out: :class:`_CompilingFirst`). Otherwise the collection order.
    """
    runs = {item: _shared_run(item) for item in items}
    users = Counter(run for run in runs.values() if run)
    builders = list({run: item for item in reversed(items) if (run := runs[item])}.values())
    builders.reverse()
    builders.sort(key=lambda item: -users[runs[item]])
    short = [i for i in items if runs[i] is None and not i.get_closest_marker("workflow")]
    first = [item for pair in zip(builders, short) for item in pair]
    chosen = set(first)
    workflow = [i for i in items if i not in chosen and i.get_closest_marker("workflow")]
    own = [i for i in workflow if runs[i] is None]
    heavy = [i for i in workflow if runs[i] and i.get_closest_marker("heavy")]
    heavy.sort(key=lambda item: -item.get_closest_marker("heavy").kwargs["cpu_s"])
    workflow = own + heavy + [i for i in workflow if i not in set(own) | set(heavy)]
    chosen.update(workflow)
    items[:] = first + workflow + [i for i in items if i not in chosen]


class _CompilingFirst:
    """After the tests not selected are left out (``-m``, ``-k``: pytest's own hook),
    the tests after the last one marked ``workflow`` (all of them in a run without the
    workflow tests) begin with those that compile numba's kernels
    (:func:`_compiling_first`). The order of the workflow tests stays as
    :func:`pytest_collection_modifyitems` made it."""

    @pytest.hookimpl(trylast=True)
    def pytest_collection_modifyitems(self, items: list[pytest.Item]) -> None:
        marked = [n for n, item in enumerate(items) if item.get_closest_marker("workflow")]
        start = marked[-1] + 1 if marked else 0
        items[start:] = _compiling_first(items[start:])


def _compiling_first(items: list[pytest.Item]) -> list[pytest.Item]:
    """``items`` with the tests that compile numba's kernels first, each followed by
    another test (xdist gives each worker two tests to start with): the one that runs
    :func:`cold_step_loop_jobs`, then one test of :func:`unit_test_kernels` per worker.
    On a fresh checkout each worker then starts compiling: one the step loop cold, the
    others a turn of the kernels each, side by side, where they used to compile each
    kernel when a test first ran it, the other worker waiting for it when it ran the
    same kind. With the kernels in numba's cache, only the order changes."""
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    cold = [i for i in items if "cold_step_loop_jobs" in i.fixturenames]
    turns = [i for i in items if "unit_test_kernels" in i.fixturenames and i not in cold]
    starters = cold[:1] + turns[:workers]
    others = [i for i in items if i not in starters]
    ordered = []
    for n, starter in enumerate(starters):
        ordered += [starter, *others[n : n + 1]]
    return ordered + others[len(starters) :]


def _shared_run(item: pytest.Item) -> str | None:
    """The fixture through which ``item`` uses a run built by :func:`built_once`: the
    last one that asks for it (a fixture that keeps something of another's run, as
    test_reproducibility.py's reference copy of the tiny run, belongs to that run)."""
    definitions = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
    if "built_once" not in item.fixturenames:
        return None
    for name in reversed(item.fixturenames):
        if any("built_once" in d.argnames for d in definitions.get(name, ())):
            return name
    return None


def _shared_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder of this test session that every xdist worker sees: the parent of the
    workers' own temporary folders; the session's own one in a serial run."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


@contextlib.contextmanager
def _exclusive(lock_file: Path, *, wait: bool = True) -> Iterator[bool]:
    """Hold an exclusive lock on ``lock_file`` (POSIX ``flock``, as the suite's
    interruption tests are POSIX-only anyway): one worker at a time gets past it.
    Yields whether this worker holds it: always with ``wait``, else only if no other
    worker did."""
    import fcntl

    with lock_file.open("a") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            yield False
            return
        try:
            yield True
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


@pytest.fixture(scope="session")
def built_once(tmp_path_factory) -> Callable[[str, Callable[[Path], None]], Path]:
    """``built_once(name, build) -> folder``: ``build(folder)`` runs once in the whole
    test session, in the first worker that asks; the others wait for it, then get the
    same folder. What is built there is shared: a test that changes it works on a copy.
    A build that fails is not marked done (the next worker tries again and fails the
    same way, with its own message)."""
    shared = _shared_folder(tmp_path_factory)

    def once(name: str, build: Callable[[Path], None]) -> Path:
        folder, done = shared / name, shared / f"{name}.done"
        with _exclusive(shared / f"{name}.lock"):
            if not done.exists():
                shutil.rmtree(folder, ignore_errors=True)
                # Private whatever the umask: a run checks the folders outside its checkout
                # (a store, numba's cache) and refuses one its group may write in.
                folder.mkdir(mode=0o700)
                build(folder)
                done.touch()
        return folder

    return once


# ---- the step loop compiled cold, once -------------------------------------------------

#: One job on a node: imports, says so, waits for the go, simulates the paper's
#: collision on a short chain, reports how numba got the step loop (compiled: a cache
#: miss; loaded: a hit) and a digest of the forces. The job that compiled it (every
#: callee too, in this process) also reports the versions numba made, then runs a long
#: chain launched from one end (chain.physics.at_rest skips its far beads, calling the
#: step loop from Python on parts of the chain) and reports them again.
COLD_JOB = """\
import hashlib, json, sys
from chain.physics import kernels
from chain.physics.builders import uniform_chain
from chain.physics.simulation import simulate
print("ready", flush=True)
sys.stdin.readline()
result = simulate(uniform_chain(8), 0.3, 0.3, duration=2e-4)
stats = kernels._integrate_part.stats
report = {
    "misses": sum(stats.cache_misses.values()),
    "hits": sum(stats.cache_hits.values()),
    "digest": hashlib.sha256(result.contact_force.tobytes()).hexdigest(),
}
if report["misses"]:
    report["whole"] = sorted(map(str, kernels._integrate_part.signatures))
    report["records"] = sorted(map(str, kernels._record.overloads))
    simulate(uniform_chain(400), [0.5], [0.0], duration=2e-4)
    report["after_at_rest"] = sorted(map(str, kernels._integrate_part.signatures))
print(json.dumps(report), flush=True)
"""


#: The folder of :func:`cold_step_loop_jobs`' run, and the name of its lock.
COLD_STEP_LOOP = "cold-step-loop"


@pytest.fixture(scope="session")
def cold_step_loop_jobs(request) -> tuple[list[dict], Path]:
    """Three jobs (:data:`COLD_JOB`) started together on a node whose numba cache
    (NUMBA_CACHE_DIR, empty) lacks the step loop, let go only once all three have
    imported the library: (their reports, the cache folder). Run once per session
    (:func:`built_once`), for the tests of tests/test_compile_once.py (one job
    compiles, the others wait and load) and tests/test_kernels.py (what the compiling
    job's numba made), which would otherwise each compile the step loop cold in a
    process of their own. :func:`built_once` is asked for here, not as an argument:
    :func:`pytest_collection_modifyitems` orders the tests of a workflow run by their
    arguments, and places these itself."""
    import json
    import subprocess
    import sys

    def build(folder: Path) -> None:
        env = {**os.environ, "NUMBA_CACHE_DIR": str(folder / "numba")}
        jobs = [
            subprocess.Popen(
                [sys.executable, "-c", COLD_JOB],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                text=True,
                env=env,
            )
            for _ in range(3)
        ]
        for job in jobs:
            assert job.stdout.readline().strip() == "ready", job.stderr.read()
        for job in jobs:
            job.stdin.write("go\n")
            job.stdin.flush()
        reports = []
        for job in jobs:
            out, err = job.communicate(timeout=900)
            assert job.returncode == 0, err[-3000:]
            reports.append(json.loads(out.splitlines()[-1]))
        (folder / "reports.json").write_text(json.dumps(reports))

    folder = request.getfixturevalue("built_once")(COLD_STEP_LOOP, build)
    return json.loads((folder / "reports.json").read_text()), folder / "numba"


# ---- the tiny run: the workflow tests' one build --------------------------------------

#: The workflow tests' config, overlaid on config.yaml: every rule on short chains.
TINY_CONFIG = ROOT / "tests" / "configs" / "tiny.yaml"

#: Not copied into the tiny run's checkout: caches and earlier results.
_NOT_COPIED = shutil.ignore_patterns("__pycache__", "*.pyc", "results", ".snakemake")

#: Longest the tiny run's build may take, s: a guard against a hang, far above its
#: minutes on a machine shared with the other worker (pytest-xdist) or other work.
_BUILD_TIMEOUT = 1800


@pytest.fixture(scope="session")
def tiny_run(built_once, copy_library) -> Path:
    """The tiny run (:data:`TINY_CONFIG`), built from nothing with ``--cores 2`` once per
    test session (:func:`built_once`) in a copy of the checkout: Snakefile, workflow/,
    profiles/, config.yaml and the library in src/ (:func:`copy_library`), started
    there as a user would: the copy's folder, its results in ``results/tiny/``.

    test_workflow.py and test_reproducibility.py both inspect it; a test that changes
    it (a rebuild, an edit, another run) works on a copy."""

    def build(base: Path) -> None:
        work = base / "checkout"
        work.mkdir()
        for name in ("config.yaml", "Snakefile"):
            shutil.copy(ROOT / name, work / name)
        for name in ("workflow", "profiles"):
            shutil.copytree(ROOT / name, work / name, ignore=_NOT_COPIED)
        env = copy_library(work / "src")
        snakefile = ["--snakefile", str(work / "Snakefile"), "--directory", str(work)]
        command = [sys.executable, "-m", "snakemake", *snakefile, "--cores", "2"]
        command += ["--configfile", str(TINY_CONFIG)]
        result = subprocess.run(
            command, cwd=work, env=env, capture_output=True, text=True, timeout=_BUILD_TIMEOUT
        )
        assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]

    return built_once("tiny", build) / "checkout"


# ---- the library in a workflow run's own folder -----------------------------------------


@pytest.fixture(scope="session")
def copy_library(compiled_kernels) -> Callable[[Path], dict]:
    """``copy_library(folder) -> env``: the checkout's ``chain`` package copied to
    ``folder/chain`` with numba's compiled kernels, and :func:`library_env`, the
    environment under which a Snakemake run imports that copy; a test may edit it.

    numba's cache index checks a source file's time and size, which copy2 keeps: the
    copy's jobs load the kernels the checkout compiled (:func:`compiled_kernels`)
    instead of compiling them again, in each job. They are in the copy's __pycache__
    folders, so a copy of the copy has them too."""
    source = ROOT / "src" / "chain"

    def copy(folder: Path) -> dict:
        target = folder / "chain"
        shutil.copytree(source, target, copy_function=shutil.copy2)
        if os.environ.get("NUMBA_CACHE_DIR"):
            # numba then keeps kernels in a folder named by the package's path (CI
            # caches it): the copy's jobs would compile them again. The same files go
            # in the copy's __pycache__, where numba looks without NUMBA_CACHE_DIR.
            _copy_user_numba_cache(source, target, Path(os.environ["NUMBA_CACHE_DIR"]))
        return library_env(folder)

    return copy


def library_env(folder: Path) -> dict:
    """The environment of a Snakemake run whose jobs import the library copied by
    :func:`copy_library` into ``folder``: on ``PYTHONPATH``, numba's kernels in-tree,
    the result store the work tree's own (``results/.store``, whatever
    ``HERTZCHAIN_STORE`` says outside the tests)."""
    env = {**os.environ, "PYTHONPATH": str(folder)}
    for name in ("NUMBA_CACHE_DIR", "HERTZCHAIN_STORE", "HERTZCHAIN_STORE_GROUP"):
        env.pop(name, None)
    return env


@pytest.fixture(scope="session")
def env_of_library() -> Callable[[Path], dict]:
    """``env_of_library(folder) -> env``: :func:`library_env` (a library copied earlier,
    by :func:`copy_library`, perhaps in another worker)."""
    return library_env


def _copy_user_numba_cache(source: Path, target: Path, cache_dir: Path) -> None:
    """The kernels numba cached for the package ``source`` under NUMBA_CACHE_DIR
    ``cache_dir``, copied into the __pycache__ folders of its copy ``target``."""
    from numba.core.caching import _CacheLocator  # how numba names a package's folder

    for folder in sorted({path.parent for path in source.rglob("*.py")}):
        subpath = _CacheLocator.get_suitable_cache_subpath(str(folder / "_.py"))
        if (cache_dir / subpath).is_dir():
            copied = target / folder.relative_to(source) / "__pycache__"
            shutil.copytree(
                cache_dir / subpath, copied, copy_function=shutil.copy2, dirs_exist_ok=True
            )


@pytest.fixture(scope="session")
def compiled_kernels(tmp_path_factory) -> None:
    """numba's kernels for the kinds of model the workflow runs, compiled into the
    checkout's cache once for all workers, before a workflow run copies the library
    (:func:`copy_library`); :func:`_compile_in_turns`."""
    _compile_in_turns(_shared_folder(tmp_path_factory), _KERNEL_KINDS)


@pytest.fixture(scope="session")
def unit_test_kernels(request, tmp_path_factory) -> None:
    """The kernels that the unit tests of the integrator run: the workflow's and those
    with walls or track drag and the reference kernel, compiled in turns by the xdist
    workers (:func:`_compile_in_turns`) when the first of those tests starts in each
    (one per worker, first of all: :func:`_compiling_first`).

    Without it, two workers that reached the kernel tests together met on the same
    version: one compiled it, the other waited for it with its core idle (twice ~7 s at
    the end of a 2-worker run; these two test files alone, 2 workers, fresh clone:
    54.6-57.5 s before, 48.2-52.0 s with it). Only where it pays: with more than one
    worker and a session that runs more of these tests than twice the kernels. A
    serial run, or a few tests picked (after an edit of the kernels, whose cache it
    empties), compile what they run: one or two kernels, not six."""
    users = sum("unit_test_kernels" in item.fixturenames for item in request.session.items)
    workers = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    kinds = _KERNEL_KINDS + _UNIT_TEST_KERNELS
    if workers > 1 and users > 2 * len(kinds):
        _compile_in_turns(_shared_folder(tmp_path_factory), kinds, wait=False)


def _compile_in_turns(shared: Path, kinds: tuple, *, wait: bool = True) -> None:
    """Run each of ``kinds`` (name, model keywords, kernel) once, which compiles it or
    loads it from numba's cache, taking turns with the other workers.

    One lock per kind. A worker takes the first kind, from its own place in the list
    (worker gw0 from the first, gw1 from the second, ...), that no other worker holds:
    two workers compile two kinds at once, then each loads the other's from the cache.
    When every kind left is held by another worker, it waits for each (``wait``) or
    returns, and a test that runs one waits for it in chain.physics.compile_once. A kind
    whose cache entry was lost (two workers writing numba's index of the same function
    at once) is compiled again by the next worker that runs it, so with ``wait`` every
    kind is in the cache when this returns."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    first = int(worker[2:]) if worker[2:].isdigit() else 0
    pending = [kinds[(first + turn) % len(kinds)] for turn in range(len(kinds))]
    while pending:
        for kind in pending:
            with _exclusive(shared / f"kernels-{kind[0]}.lock", wait=False) as mine:
                if mine:
                    _run_kernel(*kind[1:])
                    pending.remove(kind)
                    break
        else:  # the others are compiling every kind left
            if not wait:
                return
            name, model, kernel = pending.pop(0)
            with _exclusive(shared / f"kernels-{name}.lock"):
                _run_kernel(model, kernel)


#: The kinds of model the workflow's jobs simulate: elastic and damped chains with no
#: wall and no drag (the paper run's cache holds exactly these two).
_KERNEL_KINDS = (("elastic", {}, "lean"), ("damped", {"eta": PAPER_ETA}, "lean"))

#: What the unit tests of tests/test_integrator.py and tests/test_kernels.py compile
#: beyond :data:`_KERNEL_KINDS` (which they run too, as most other tests do): the
#: general kernel, and the lean kernel of a chain with walls, damped or not, and of one
#: with track drag.
_UNIT_TEST_KERNELS = (
    ("reference", {"eta": PAPER_ETA, "right_wall": True}, "reference"),
    ("walls-damped", {"eta": PAPER_ETA, "right_wall": True}, "lean"),
    ("walls-elastic", {"left_wall": True}, "lean"),
    ("drag-damped", {"eta": PAPER_ETA, "drag_rate": 30.0}, "lean"),
)


def _run_kernel(kind: dict, kernel: str = "lean") -> None:
    """One short run of ``kernel`` on a chain of this kind: numba compiles one lean
    kernel per kind of model (Kuwabara-Kono damping, walls, track drag present or not;
    chain.physics.slopes), which also serves a long chain whose beads at rest are
    skipped (chain.physics.at_rest), and one general kernel; or loads it from its cache."""
    from chain import uniform_chain
    from chain.physics.integrator import integrate

    model = uniform_chain(4, **kind)
    velocity = np.zeros(model.n_particles)
    velocity[0] = 0.1
    integrate(model, velocity, 1e-5, 1e-7, kernel=kernel)
