"""Benchmark of the simulation against its yardsticks, as ratios measured in one run.

Run from the repository root::

    python benchmarks/bench_integrator.py              # best of 7 interleaved runs
    python benchmarks/bench_integrator.py --repeat 9 --skip-long
    python benchmarks/bench_integrator.py --baseline /tmp/k9fb/src   # and 9fb9b1b's

It prints, for one collision in the paper's chain (N = 26, +V0 / -V0 at V0 = 0.3 m/s,
2 ms simulated, records every 1 us, the default step):

1. **chain.simulate / C** (target <= 1.3): the call a user makes, with its defaults
   (every contact force and bead velocity, the energies, contact-event refinement, the
   energy check), against a plain C RK4 (``benchmarks/c/rk4_chain.c``, compiled now
   with ``cc -O3 -march=native``; skipped with a message when there is no compiler)
   at the same step; also ``integrate`` (the lean kernel behind it) and the general
   reference kernel against C; elastic and Kuwabara-Kono; with ``--baseline SRC``,
   also ``chain.simulate`` of another commit's source tree (its package loaded under
   another name), interleaved in the same rounds, and whether it gives the same bits;
   then (1b) the lean kernel carrying walls of zero stiffness, and a negligible track
   friction, against itself without them: what a term costs when numba compiles it in
   (reported, no target; 7.1 and 3.3 before 27 Nov 2026, when these terms cost
   reference-count updates at every right-hand side);
2. **DOP853 / kernel**: scipy ``solve_ivp(method="DOP853")`` on a numba right-hand
   side, at the loosest rtol of a fine grid (8 per decade) that reaches both the
   kernel's energy drift and its force error against a reference solution; reported,
   no target (it measures scipy's step overhead more than the kernel);
3. **batch**: a 16-amplitude sweep in one call on all threads against the same call on
   one thread (bit-identical results), and per launch against C;
4. **a long chain with the defaults** (unless ``--skip-long``): 10,000 beads x 5 ms
   through ``chain.simulate`` with its defaults on one core, in a child process
   (targets < 4 s and < 300 MB peak resident memory), against C at the same step.

Measurement discipline (``benchmarks/measure.py``): every time is the best of
``--repeat`` (>= 7) interleaved runs, single launches in CPU time (one thread), the
batch in wall time; the load average is printed before and after, and a figure taken
with a load average above the number of cores is reported as "UNDER LOAD — not a
measurement of the target", never as met. Not a test: it asserts nothing, it reports.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np
import scipy
from measure import (
    C_FLAGS,
    MIN_REPEAT,
    Conditions,
    Figure,
    OtherProcesses,
    best_times,
    load_c,
    machine,
    peak_memory_mb,
    write_result,
)
from measure import c_run as c_run_equal
from scipy.integrate import solve_ivp

from chain.physics import kernels
from chain.physics.builders import uniform_chain
from chain.physics.integrator import integrate
from chain.physics.kernels import EVENT_AFTERMATH, EVENT_SUBSTEPS, _integrate_one
from chain.physics.launches import _lean_params, _outputs
from chain.physics.materials import STEEL_100C6, contact_stiffness, sphere_mass
from chain.physics.model import launch_velocities
from chain.physics.simulation import default_time_step, simulate

N_BEADS = 26
DURATION = 2e-3  # s
SPEED = 0.3  # m/s
RECORD_INTERVAL = 1e-6  # s
ETA = 0.58e-6  # s, the paper's Kuwabara-Kono time
RADIUS = 13e-3  # m
BATCH_SPEEDS = np.geomspace(0.02, 1.0, 16)  # m/s
LONG_N = 10_000  # beads of section 4
LONG_DURATION = 5e-3  # s


def c_run(function, velocity, eta: float, dt: float, n_steps: int, record_every: int):
    """One C run of launch ``velocity`` in the benchmark's chain; returns (contact
    forces (S, N-1), energy (S,))."""
    mass = sphere_mass(STEEL_100C6, RADIUS)
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    return c_run_equal(function, velocity, mass, kappa, eta, dt, n_steps, record_every)


@numba.njit(cache=True)
def _numba_rhs(_t, y, inverse_mass, kappa):
    # Eq. 1, equal beads, free ends, as a right-hand side for solve_ivp.
    n = y.shape[0] // 2
    out = np.empty_like(y)
    previous = 0.0
    for j in range(n - 1):
        delta = y[j] - y[j + 1]
        force = kappa * delta * math.sqrt(delta) if delta > 0.0 else 0.0
        out[n + j] = (previous - force) * inverse_mass
        previous = force
    out[2 * n - 1] = previous * inverse_mass
    out[:n] = y[n:]
    return out


def dop853(rtol: float, velocity, samples):
    """DOP853 with the numba right-hand side; returns (forces (S, N-1), drift)."""
    mass = sphere_mass(STEEL_100C6, RADIUS)
    kappa = contact_stiffness(STEEL_100C6, RADIUS, STEEL_100C6, RADIUS)
    n = len(velocity)
    y0 = np.r_[np.zeros(n), velocity]
    # Absolute tolerances on the scale of the state: overlaps ~ 1e-5 m, speeds ~ V0.
    atol = np.r_[np.full(n, 1e-5 * rtol), np.full(n, SPEED * rtol)] * 1e-3
    solution = solve_ivp(
        _numba_rhs,
        (0.0, samples[-1]),
        y0,
        method="DOP853",
        rtol=rtol,
        atol=atol,
        t_eval=samples,
        args=(1.0 / mass, kappa),
    )
    overlap = np.maximum(solution.y[: n - 1] - solution.y[1:n], 0.0)
    energy = 0.5 * mass * np.sum(solution.y[n:] ** 2, axis=0)
    energy += 0.4 * kappa * np.sum(overlap**2.5, axis=0)
    drift = float(np.max(np.abs(energy - energy[0])) / energy[0])
    return (kappa * overlap**1.5).T, drift


def patched_kernel(
    folder: Path, substeps: int, aftermath: int, refine: bool, edits=(), name: str = ""
):
    """A copy of chain.physics.kernels with another refinement scheme and the source
    ``edits`` ((old, new) pairs), compiled with numba's cache off, as a module."""
    source = Path(kernels.__file__).read_text()
    edits = [
        ("EVENT_SUBSTEPS = 16", f"EVENT_SUBSTEPS = {substeps}"),
        ("EVENT_AFTERMATH = 3", f"EVENT_AFTERMATH = {aftermath}"),
        ("cache=CACHE", "cache=False"),
        *edits,
    ]
    if not refine:  # detect events (same work, refined code present) but keep the coarse step
        edits.append(
            (
                "                if event:  # redone in substeps below\n",
                "                if event and dt < 0.0:  # never true; numba cannot know it\n",
            )
        )
    for old, new in edits:
        assert old in source, f"kernels.py changed: {old!r} not found"
        source = source.replace(old, new)
    name = name or f"kernel_{substeps}_{aftermath}_{int(refine)}"
    path = folder / f"{name}.py"
    path.write_text(source)
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def baseline_package(src: Path):
    """The ``chain`` package of the source tree ``src`` (another commit's), copied and
    imported as ``chain_baseline`` beside this tree's; returns it."""
    folder = Path(tempfile.mkdtemp())
    shutil.copytree(
        src / "chain", folder / "chain_baseline", ignore=shutil.ignore_patterns("__pycache__")
    )
    for path in (folder / "chain_baseline").rglob("*.py"):
        text = path.read_text()
        text = text.replace("from chain.", "from chain_baseline.").replace(
            "from chain import", "from chain_baseline import"
        )
        text = text.replace("import chain.", "import chain_baseline.")
        path.write_text(text.replace('"chain.', '"chain_baseline.'))  # lazy imports
    sys.path.insert(0, str(folder))
    return importlib.import_module("chain_baseline")


def kernel_against_c(args, c_function) -> dict:
    """Section 1: chain.simulate (defaults), the lean and the reference kernel against C
    at the default step; returns {label: (simulate / C, integrate / C)}."""
    results = {}
    folder = tempfile.mkdtemp()
    unrefined = patched_kernel(Path(folder), EVENT_SUBSTEPS, EVENT_AFTERMATH, False)
    old = None if args.baseline is None else baseline_package(args.baseline)
    for eta in (0.0, ETA):
        model = uniform_chain(N_BEADS, eta=eta)
        velocity = launch_velocities(model, SPEED, SPEED)
        dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, SPEED))
        every = round(RECORD_INTERVAL / dt)
        n_steps = math.ceil(DURATION / dt - 1e-9)

        def run(kernel, model=model, velocity=velocity, dt=dt, every=every):
            return integrate(model, velocity, DURATION, dt, every, kernel=kernel)

        contenders = {
            "simulate": lambda model=model: simulate(model, SPEED, SPEED, duration=DURATION),
            "integrate": lambda: run("lean"),
            "reference": lambda: run("reference"),
            # The bound, measured: the kernel alone, and with the refinement of contact
            # events switched off (detection kept).
            "kernel": kernel_alone(kernels, model, velocity[0], dt, n_steps, every),
            "unrefined": kernel_alone(unrefined, model, velocity[0], dt, n_steps, every),
        }
        if c_function is not None:
            contenders["C"] = lambda v=velocity[0], e=eta, d=dt, s=n_steps, r=every: c_run(
                c_function, v, e, d, s, r
            )
        if old is not None:
            old_model = old.uniform_chain(N_BEADS, eta=eta)
            contenders["baseline"] = lambda m=old_model: old.simulate(
                m, SPEED, SPEED, duration=DURATION
            )
        for function in contenders.values():
            function()  # compile
        # The reference kernel is a numba prange region (threads): wall time.
        best = best_times(contenders, args.repeat, clocks={"reference": time.perf_counter})
        label = "Kuwabara-Kono" if eta else "elastic"
        ours = run("lean")
        if simulate(model, SPEED, SPEED, duration=DURATION).dt != dt:
            print("  WARNING: simulate's default step is not the step C is timed at")
        print(f"\n{label}: dt = {dt:.4e} s, {n_steps} steps, refined {ours.refined_steps[0]}")
        for name, seconds in best.items():
            print(f"  {name:10s} {seconds * 1e3:8.2f} ms")
        if c_function is not None:
            force, energy = c_run(c_function, velocity[0], eta, dt, n_steps, every)
            difference = np.abs(ours.link_force[0] - force).max() / force.max()
            print(
                f"  force difference lean - C: {difference:.1e}"
                f" of the peak; energy drift lean {ours.energy_drift[0]:.1e}"
                + (f", C {np.abs(energy - energy[0]).max() / energy[0]:.1e}" if not eta else "")
            )
            results[label] = (best["simulate"] / best["C"], best["integrate"] / best["C"])
        if old is not None:
            results[f"{label} / baseline"] = best["simulate"] / best["baseline"]
            print(
                f"  ** simulate / C = {results[label][0]:.2f} (target <= 1.3); "
                f"integrate / C = {results[label][1]:.2f}; "
                f"reference / C = {best['reference'] / best['C']:.2f}"
            )
            print_bound(best)
        if "baseline" in best:
            same = np.array_equal(
                contenders["simulate"]().contact_force, contenders["baseline"]().contact_force
            )
            print(
                f"  ** simulate / baseline ({args.baseline}) = "
                f"{best['simulate'] / best['baseline']:.3f}; baseline / C = "
                f"{best['baseline'] / best['C']:.2f}; same contact forces: {same}"
            )
    shutil.rmtree(folder, ignore_errors=True)
    return results


def kernel_alone(module, model, velocity, dt: float, n_steps: int, every: int, params=None):
    """A launch through ``module``'s kernel, called directly (outputs allocated), with
    the model's kernel arrays or ``params``."""
    params = _lean_params(model) if params is None else params
    n = model.n_particles
    links, particles = np.arange(n - 1), np.arange(n)

    def run():
        outputs = tuple(o[0] for o in _outputs(1, n_steps // every + 1, n - 1, n))
        u, v = np.zeros(n), velocity.copy()
        module._integrate_one(u, v, params, dt, n_steps, every, links, particles, outputs)

    return run


def optional_terms(args) -> dict:
    """Section 1b: the lean kernel carrying walls of zero stiffness, and a track friction
    too weak to matter (1e-12 /s), against the kernel without them, on the elastic
    collision of section 1: what a term costs when numba compiles it in (the walls
    leave the bits unchanged). Returns {term: ratio}."""
    model = uniform_chain(N_BEADS)
    velocity = launch_velocities(model, SPEED, SPEED)[0]
    dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, SPEED))
    every = round(RECORD_INTERVAL / dt)
    n_steps = math.ceil(DURATION / dt - 1e-9)
    base = _lean_params(model)
    rate = np.full(model.n_particles, 1e-12)
    drag = np.ascontiguousarray(np.stack([rate, model.masses * rate], axis=1))
    variants = {
        "without": base,
        "walls": (*base[:6], (0.0, 0.0, 0.0, 0.0), *base[7:]),
        "drag": (*base[:7], drag, *base[8:]),
    }
    contenders = {
        name: kernel_alone(kernels, model, velocity, dt, n_steps, every, params)
        for name, params in variants.items()
    }
    for function in contenders.values():
        function()  # compile
    best = best_times(contenders, args.repeat)
    ratios = {}
    for name, seconds in best.items():
        ratio = seconds / best["without"]
        ratios[name] = ratio
        print(f"  {name:10s} {seconds * 1e3:8.2f} ms  {ratio:5.2f} x without")
    return ratios


def print_bound(best: dict) -> None:
    """Where simulate's time goes, as multiples of C, from the same run's figures."""
    c = best["C"]
    parts = {
        "plain RK4 steps and contact-event detection": best["unrefined"],
        "refinement of the steps with contact events": best["kernel"] - best["unrefined"],
        "integrate(): checks, allocation, energy check": best["integrate"] - best["kernel"],
        "simulate(): arguments, default step, bead view": best["simulate"] - best["integrate"],
    }
    print("  where simulate's time goes (x C; the differences carry the noise of two runs):")
    for name, seconds in parts.items():
        print(f"    {name:48s} {seconds / c:5.2f}")


def scan_rtol(velocity, samples, fine, our_drift, our_error):
    """DOP853 on a fine rtol grid (8 per decade, 1e-10..1e-13) against the kernel's
    drift and force error; returns (chosen rtol, robust rtol, rtols that meet both).

    DOP853's error is not monotonic in rtol, so a coarse grid would charge it for more
    accuracy than it needs. "chosen" is the loosest rtol that meets both (the ratio's
    basis, the most generous to DOP853); "robust" the loosest from which every tighter
    rtol of the grid meets both."""
    scale = fine.max()
    met = {}
    for rtol in np.geomspace(1e-10, 1e-13, 25):
        force, drift = dop853(rtol, velocity, samples)
        error = np.abs(force - fine).max() / scale
        met[rtol] = bool(drift <= our_drift and error <= our_error)
        print(
            f"  DOP853 rtol {rtol:.2e}: drift {drift:.1e}, force error {error:.1e}"
            + ("  meets both" if met[rtol] else "")
        )
    meeting = [rtol for rtol, ok in met.items() if ok]
    chosen = meeting[0] if meeting else 1e-13
    robust = next((r for r in met if all(met[t] for t in met if t <= r)), 1e-13)
    return chosen, robust, meeting


def against_dop853(args) -> float:
    """Section 2: DOP853 (numba rhs) at the kernel's drift and force error."""
    model = uniform_chain(N_BEADS)
    velocity = launch_velocities(model, SPEED, SPEED)
    dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, SPEED))
    every = round(RECORD_INTERVAL / dt)
    ours = integrate(model, velocity, DURATION, dt, every)
    # Reference: the same kernel at an eighth of the step (RK4: ~4000x smaller error),
    # checked against DOP853 at rtol 1e-13.
    fine = integrate(model, velocity, DURATION, dt / 8, 8 * every).link_force[0]
    check, check_drift = dop853(1e-13, velocity[0], ours.time)
    scale = fine.max()
    print(
        f"reference: lean kernel at dt / 8; DOP853 at rtol 1e-13 differs from it by "
        f"{np.abs(check - fine).max() / scale:.1e} of the peak (drift {check_drift:.1e})"
    )
    our_error = np.abs(ours.link_force[0] - fine).max() / scale
    our_drift = ours.energy_drift[0]
    print(f"lean kernel: energy drift {our_drift:.1e}, force error {our_error:.1e} of the peak")
    chosen, robust, meeting = scan_rtol(velocity[0], ours.time, fine, our_drift, our_error)
    if not meeting:
        print(f"  DOP853 never matched both; timed at rtol {chosen:.0e} (a lower bound)")
    best = best_times(
        {
            "lean": lambda: integrate(model, velocity, DURATION, dt, every),
            "DOP853": lambda: dop853(chosen, velocity[0], ours.time),
            "DOP853 robust": lambda: dop853(robust, velocity[0], ours.time),
        },
        args.repeat,
    )
    ratio = best["DOP853"] / best["lean"]
    lean, dop = best["lean"] * 1e3, best["DOP853"] * 1e3
    print(f"  lean {lean:.2f} ms, DOP853 (rtol {chosen:.2e}) {dop:.1f} ms")
    print(
        f"  (robust rtol {robust:.2e}: {best['DOP853 robust'] * 1e3:.1f} ms, "
        f"DOP853 / lean = {best['DOP853 robust'] / best['lean']:.1f})"
    )
    print(f"  ** DOP853 / lean = {ratio:.1f} (reported, no target)")
    return ratio


def batch(args, c_function) -> None:
    """Section 3: the amplitude sweep on all threads, on one thread, and per launch in C."""
    model = uniform_chain(N_BEADS, eta=ETA)
    velocity = launch_velocities(model, BATCH_SPEEDS, BATCH_SPEEDS)
    fastest = float(BATCH_SPEEDS.max())
    dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, fastest))
    every = round(RECORD_INTERVAL / dt)
    n_steps = math.ceil(DURATION / dt - 1e-9)
    threads = numba.get_num_threads()

    def one_thread():
        numba.set_num_threads(1)
        try:
            return integrate(model, velocity, DURATION, dt, every)
        finally:
            numba.set_num_threads(threads)

    contenders = {
        "all threads": lambda: integrate(model, velocity, DURATION, dt, every),
        "one thread": one_thread,
    }
    if c_function is not None:
        contenders["C, 16 launches"] = lambda: [
            c_run(c_function, v, ETA, dt, n_steps, every) for v in velocity
        ]
    best = best_times(contenders, args.repeat, clock=time.perf_counter)  # wall: threads
    wall, cpu = time.perf_counter(), time.process_time()
    contenders["all threads"]()
    used = (time.process_time() - cpu) / (time.perf_counter() - wall)
    same = np.array_equal(contenders["all threads"]().link_force, one_thread().link_force)
    print(f"\n16 launches, V0 = 0.02..1 m/s, Kuwabara-Kono, dt = {dt:.3e} s, {n_steps} steps")
    for name, seconds in best.items():
        print(f"  {name:16s} {seconds * 1e3:8.1f} ms = {seconds / 16 * 1e3:.2f} ms per launch")
    print(
        f"  ** one thread / all threads = {best['one thread'] / best['all threads']:.2f}"
        f" on {threads} threads; results bit-identical: {same}"
    )
    print(f"  cores busy during the all-threads call (CPU time / wall time): {used:.2f}")


def whole_chain(model, velocity, dt: float, n_steps: int, every: int) -> None:
    """The lean kernel on every bead at every step (no skipping of beads at rest,
    chain.physics.at_rest), recording every 20th contact and bead: the work C does."""
    params = _lean_params(model)
    links = np.arange(0, model.n_particles - 1, 20)
    particles = np.arange(0, model.n_particles, 20)
    outputs = tuple(o[0] for o in _outputs(1, n_steps // every + 1, links.size, particles.size))
    u = np.zeros(model.n_particles)
    _integrate_one(u, velocity.copy(), params, dt, n_steps, every, links, particles, outputs)


def long_chain_child(repeat: int) -> None:
    """Section 4, in a child process on one thread: prints one JSON line with the best
    CPU and wall time of chain.simulate's defaults on LONG_N beads and of C (interleaved),
    and the process's peak resident memory."""

    model = uniform_chain(LONG_N)
    simulate(uniform_chain(10), SPEED, SPEED, duration=1e-5)  # load the compiled kernel
    dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, SPEED))
    n_steps = math.ceil(LONG_DURATION / dt - 1e-9)
    every = round(RECORD_INTERVAL / dt)
    velocity = launch_velocities(model, SPEED, SPEED)[0]
    best = {name: [math.inf, math.inf] for name in ("simulate", "whole chain", "C")}
    first = time.perf_counter()
    simulate(model, SPEED, SPEED, duration=LONG_DURATION)
    first = time.perf_counter() - first  # seconds: numba compiled here if it is long
    # Before C runs: C's record of every contact (400 MB) is not simulate's memory.
    peak_mb = peak_memory_mb()
    with tempfile.TemporaryDirectory() as folder:
        c_function, _ = load_c(folder)
        contenders = {
            "simulate": lambda: simulate(model, SPEED, SPEED, duration=LONG_DURATION),
            "whole chain": lambda: whole_chain(model, velocity, dt, n_steps, every),
        }
        if c_function is not None:
            # C records every contact: with the record of the defaults (an overview) it
            # would be a little faster still; the record is a small part of its work.
            contenders["C"] = lambda: c_run(c_function, velocity, 0.0, dt, n_steps, every)
        for _ in range(repeat):
            for name, function in contenders.items():
                cpu, wall = time.process_time(), time.perf_counter()
                function()
                best[name][0] = min(best[name][0], time.process_time() - cpu)
                best[name][1] = min(best[name][1], time.perf_counter() - wall)
    print(
        json.dumps(
            {
                "simulate_cpu_s": best["simulate"][0],
                "simulate_wall_s": best["simulate"][1],
                "c_cpu_s": best["C"][0] if c_function is not None else None,
                "whole_cpu_s": best["whole chain"][0],
                "peak_mb": peak_mb,
                "first_call_s": first,
                "steps": n_steps,
            }
        )
    )


def long_chain(args) -> dict:
    """Section 4: the child process's figures."""
    environment = {**os.environ, "NUMBA_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    command = [sys.executable, __file__, "--long-child", "--repeat", str(args.repeat)]
    done = subprocess.run(command, capture_output=True, text=True, env=environment, check=True)
    figures = json.loads(done.stdout.strip().splitlines()[-1])
    print(
        f"{LONG_N} beads x {LONG_DURATION * 1e3:g} ms, defaults (overview record), one "
        f"thread, {figures['steps']} steps: simulate {figures['simulate_cpu_s']:.2f} s CPU "
        f"({figures['simulate_wall_s']:.2f} s wall), peak {figures['peak_mb']:.0f} MB "
        f"(first call {figures['first_call_s']:.2f} s)"
        + (
            f"; C {figures['c_cpu_s']:.2f} s, simulate / C = "
            f"{figures['simulate_cpu_s'] / figures['c_cpu_s']:.2f}"
            if figures["c_cpu_s"]
            else ""
        )
    )
    whole = figures["whole_cpu_s"]
    print(
        "  simulate skips the beads the waves have not reached (chain.physics.at_rest; same "
        f"bits), C integrates all {LONG_N}. The lean kernel on every bead: {whole:.2f} s"
        + (f" = {whole / figures['c_cpu_s']:.2f} x C" if figures["c_cpu_s"] else "")
        + " (its branch-free passes compute every open contact, which C's branch skips)"
    )
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--repeat", type=int, default=MIN_REPEAT, help=f"interleaved rounds (>= {MIN_REPEAT})"
    )
    parser.add_argument("--skip-long", action="store_true", help="skip section 4")
    parser.add_argument(
        "--baseline", type=Path, help="another commit's src/, timed in section 1 too"
    )
    parser.add_argument("--long-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.long_child:
        long_chain_child(args.repeat)
        return
    conditions = Conditions()
    print(f"machine: {machine()}, numba threads {numba.get_num_threads()}")
    print(
        f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}"
        f", numba {numba.__version__}; C flags: {' '.join(C_FLAGS)}"
    )
    conditions.sample("before")
    with tempfile.TemporaryDirectory() as folder, OtherProcesses(interval=1.0) as others:
        c_function, how = load_c(folder)
        print(f"C yardstick: {how}" if c_function else f"C yardstick skipped: {how}")
        print("\n== 1. chain.simulate / C, one collision, N = 26, V0 = 0.3 m/s, 2 ms, 1 us")
        ratios = kernel_against_c(args, c_function)
        print("\n== 1b. walls of zero stiffness, track friction of 1e-12 /s: kernel / without")
        terms = optional_terms(args)
        print("\n== 2. DOP853 (numba right-hand side) / kernel, same accuracy (no target)")
        dop = against_dop853(args)
        print("\n== 3. batch")
        batch(args, c_function)
        if not args.skip_long:
            print("\n== 4. a long chain through chain.simulate's defaults, one core")
            conditions.sample("between")
            long = long_chain(args)
    conditions.sample("after")
    print(f"\n== summary (measured in this run, best of {args.repeat} interleaved)")
    baselines = {k: ratios.pop(k) for k in list(ratios) if k.endswith(" / baseline")}
    for label, ratio in baselines.items():
        verdict = conditions.verdict(ratio <= 1.0)
        print(f"chain.simulate ({label}): {ratio:.3f}  (target <= 1: {verdict})")
    for label, (user, kernel) in ratios.items():
        verdict = conditions.verdict(user <= 1.3)
        print(f"chain.simulate / C ({label}): {user:.2f}  (target <= 1.3: {verdict})")
        print(f"  integrate (lean kernel) / C ({label}): {kernel:.2f}")
    print(
        f"kernel with walls / without: {terms['walls']:.2f}, with track friction / without: "
        f"{terms['drag']:.2f}  (reported, no target)"
    )
    print(f"DOP853 / kernel: {dop:.1f}  (reported, no target)")
    if not args.skip_long:
        seconds, megabytes = long["simulate_cpu_s"], long["peak_mb"]
        print(
            f"{LONG_N} beads x 5 ms, defaults: {seconds:.2f} s, {megabytes:.0f} MB  (targets "
            f"< 4 s: {conditions.verdict(seconds < 4)}; < 300 MB: "
            f"{'met' if megabytes < 300 else 'not met'}, memory is not load-dependent)"
        )
    long = None if args.skip_long else long
    figures = summary_figures(args, ratios, baselines, terms, dop, long, conditions)
    write_result("bench_integrator", figures, conditions, others.share)


def summary_figures(args, ratios, baselines, terms, dop, long, conditions) -> list:
    """The summary's figures, for benchmarks/results/bench_integrator.json."""
    c = f"C RK4 ({' '.join(C_FLAGS)}), same run"
    figures = []
    for label, (user, kernel) in ratios.items():
        figures += [
            Figure(f"chain.simulate / C ({label})", user, "x",
                   "plain RK4 steps plus contact-event detection and refinement", c,
                   "<= 1.3", conditions.verdict(user <= 1.3)),
            Figure(f"integrate (lean kernel) / C ({label})", kernel, "x",
                   "the kernel's steps (no fused multiply-add: same bits)", c),
        ]  # fmt: skip
    for label, ratio in baselines.items():
        figures.append(
            Figure(f"chain.simulate ({label})", ratio, "x", "the same RK4 steps",
                   f"{args.baseline}'s chain.simulate, same run", "<= 1",
                   conditions.verdict(ratio <= 1.0))
        )  # fmt: skip
    figures += [
        Figure("kernel with walls / without", terms["walls"], "x", "the term compiled in",
               "the kernel without walls, same run"),
        Figure("kernel with track friction / without", terms["drag"], "x",
               "the term compiled in", "the kernel without friction, same run"),
        Figure("DOP853 / kernel", dop, "x", "scipy's step overhead",
               "the kernel at the same accuracy, same run"),
    ]  # fmt: skip
    if long is not None:
        seconds, megabytes = long["simulate_cpu_s"], long["peak_mb"]
        figures += [
            Figure(f"{LONG_N} beads x 5 ms, CPU", seconds, "s", "the beads the waves reach",
                   None, "< 4 s", conditions.verdict(seconds < 4)),
            Figure(f"{LONG_N} beads x 5 ms, peak memory", megabytes, "MB",
                   "interpreter, numba, record", None, "< 300 MB",
                   "met" if megabytes < 300 else "not met"),
        ]  # fmt: skip
    return figures


if __name__ == "__main__":
    main()
