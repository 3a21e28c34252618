"""Where chain.simulate's time goes, against C and DOP853.

Run from the repository root::

    python benchmarks/kernel_breakdown.py              # elastic, as in the DOP853 section
    python benchmarks/kernel_breakdown.py --eta 0.58e-6 --speed 1.0

One collision in the paper's chain (N = 26, +V0 / -V0, 2 ms, every contact force,
velocity and the energies recorded every 1 us) at the default step. CPU times, best of
``--repeat`` interleaved rounds, of:

* ``simulate()``: the call a user makes, with its defaults (every contact and bead);
* ``integrate()``: the lean kernel's public wrapper, which ``simulate`` calls;
* the C yardstick (``benchmarks/c/rk4_chain.c``, ``-O3 -march=native``) at the same step;
* ``integrate()`` for one step (the wrapper's fixed cost);
* the numba kernel called directly, with freshly allocated outputs and with outputs
  allocated once before (integrate() minus this is the wrapper and the allocation,
  whose cost depends on the state of the memory allocator: 0.1 to 0.7 ms measured),
  and recording only the first and last sample (the difference is the recording);
* patched copies of ``chain/physics/kernels.py`` (compiled here, cache off): contact
  events detected but the coarse step kept ("no refinement": the difference is what
  the refinement costs), and other refinement schemes (EVENT_SUBSTEPS substeps for the
  event step and the EVENT_AFTERMATH steps after it), each with its energy drift and
  its force error against the reference solution (the kernel at dt / 8), the two
  accuracies bench_integrator.py matches DOP853 to, and its "event error": the largest
  force and energy difference from the converged scheme (64 substeps, 12 steps after)
  at the same dt, the error the scheme itself adds at contact events.

With ``--split``, only what splitting the step loop (``kernels._integrate_part``, 62
lines of code) into named steps would cost: the loop as it is against a copy whose
(sub)steps of one step are a helper of their own (:func:`split_edits`), elastic and
Kuwabara-Kono, same bits checked; writes ``kernel_split.json``.

A diagnostic, not a test: it asserts only that the patched lines still exist.
"""

from __future__ import annotations

import argparse
import math
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np
from bench_integrator import c_run, dop853, patched_kernel
from measure import C_FLAGS, MIN_REPEAT, Conditions, Figure, best_times, load_c, write_result

from chain.physics import kernels
from chain.physics.builders import uniform_chain
from chain.physics.integrator import integrate
from chain.physics.kernels import EVENT_AFTERMATH, EVENT_SUBSTEPS
from chain.physics.launches import _lean_params, _outputs
from chain.physics.model import launch_velocities
from chain.physics.simulation import default_time_step, simulate

N_BEADS = 26
DURATION = 2e-3  # s
RECORD_INTERVAL = 1e-6  # s

#: (label, substeps, aftermath, refine at all)
SCHEMES = (
    ("no refinement", 16, 3, False),
    ("16 substeps, aftermath 0", 16, 0, True),
    ("16 substeps, aftermath 1", 16, 1, True),
    ("4 substeps, aftermath 3", 4, 3, True),
    ("8 substeps, aftermath 3", 8, 3, True),
    ("64 substeps, aftermath 12", 64, 12, True),
)
CONVERGED = "64 substeps, aftermath 12"


def split_edits(source: str) -> list:
    """Edits of kernels.py's ``source`` that split its step loop: the (sub)steps of one
    step (from ``h = dt / substeps`` to ``in_y = not in_y``) move into a helper,
    ``_substeps``, compiled once by numba and inlined by LLVM (forceinline) as
    ``_plain_step`` is; the loop calls it."""
    first, last = "            h = dt / substeps\n", "                in_y = not in_y\n"
    start = source.index(first)
    block = source[start : source.index(last, start) + len(last)]
    arguments = (
        "in_y, x_u, x_v, x_acc, y_u, y_v, y_acc, work, slope, dt, substeps, "
        "im, k, c, keys, springs, walls, drag"
    )
    helper = (
        "@numba.njit(cache=False, forceinline=True)\n"
        f"def _substeps({arguments}):\n"
        f"{textwrap.indent(textwrap.dedent(block), '    ')}"
        "    return increment, end, varied, in_y\n\n\n"
    )
    call = f"            increment, end, varied, in_y = _substeps({arguments})\n"
    return [(block, call), ("@compile_once.shared\n", helper + "@compile_once.shared\n")]


def split_cost(repeat: int, speed: float) -> None:
    """The step loop whole (as in kernels.py) against split (:func:`split_edits`), both
    copies compiled here with the cache off, for an elastic and a Kuwabara-Kono chain
    (the paper's eta) launched at ``speed`` m/s: the first call's CPU time (the
    compile, after a third copy compiled the shared right-hand side) and the best of
    ``repeat`` interleaved rounds. Writes kernel_split.json."""
    conditions = Conditions()
    conditions.sample("before")
    source = Path(kernels.__file__).read_text()
    folder = Path(tempfile.mkdtemp())
    copies = {
        name: patched_kernel(folder, EVENT_SUBSTEPS, EVENT_AFTERMATH, True, edits, name)
        for name, edits in (("warm_up", ()), ("whole", ()), ("split", split_edits(source)))
    }
    contenders, compile_s, runs = {}, {}, {}
    links, particles = np.arange(N_BEADS - 1), np.arange(N_BEADS)
    for kind, eta in (("elastic", 0.0), ("Kuwabara-Kono", 0.58e-6)):
        model = uniform_chain(N_BEADS, eta=eta)
        velocity = launch_velocities(model, speed, speed)
        dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, speed))
        every = round(RECORD_INTERVAL / dt)
        n_steps = math.ceil(DURATION / dt - 1e-9)
        params = _lean_params(model)
        for name, module in copies.items():
            out = tuple(o[0] for o in _outputs(1, n_steps // every + 1, N_BEADS - 1, N_BEADS))

            def run(module=module, out=out, velocity=velocity[0], params=params, dt=dt,
                    n_steps=n_steps, every=every):  # fmt: skip
                u, v = np.zeros(N_BEADS), velocity.copy()
                status = module._integrate_one(
                    u, v, params, dt, n_steps, every, links, particles, out
                )
                return [*out, u, v], status

            start = time.process_time()
            runs[name, kind] = run()
            compile_s[name, kind] = time.process_time() - start
            if name != "warm_up":
                contenders[name, kind] = run
    best = best_times(contenders, repeat)
    conditions.sample("after")
    figures = []
    for kind in ("elastic", "Kuwabara-Kono"):
        (whole, whole_status), (split, split_status) = runs["whole", kind], runs["split", kind]
        same = whole_status == split_status and all(map(np.array_equal, whole, split))
        ratio = best["split", kind] / best["whole", kind]
        extra = compile_s["split", kind] - compile_s["whole", kind]
        print(
            f"{kind}: whole {best['whole', kind] * 1e3:.3f} ms, split "
            f"{best['split', kind] * 1e3:.3f} ms (split / whole {ratio:.4f}, best of "
            f"{repeat}); first call whole {compile_s['whole', kind]:.2f} s, split "
            f"{compile_s['split', kind]:.2f} s; same bits: {same}"
        )
        figures += [
            Figure(
                f"step loop split / whole, {kind}",
                ratio,
                "x",
                "the same arithmetic, the helper inlined by LLVM"
                + ("" if same else "; BITS DIFFER"),
                "the whole step loop (kernels.py), same rounds",
            ),
            Figure(
                f"step loop split, extra compile, {kind}",
                extra,
                "s",
                "numba types and lowers the helper on its own before LLVM inlines it",
            ),
        ]
    write_result("kernel_split", figures, conditions)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=MIN_REPEAT)
    parser.add_argument(
        "--split", action="store_true", help="only what splitting the step loop costs"
    )
    parser.add_argument("--eta", type=float, default=0.0, help="Kuwabara-Kono time, s")
    parser.add_argument("--speed", type=float, default=0.3, help="V0, m/s")
    parser.add_argument(
        "--rtol",
        type=float,
        nargs="*",
        default=[1.33e-12, 4.22e-13],
        help="also time DOP853 (bench_integrator.dop853, elastic only) at these rtol",
    )
    args = parser.parse_args()
    if args.split:
        split_cost(args.repeat, args.speed)
        return
    conditions = Conditions()
    conditions.sample("before")
    model = uniform_chain(N_BEADS, eta=args.eta)
    velocity = launch_velocities(model, args.speed, args.speed)
    dt = RECORD_INTERVAL / math.ceil(RECORD_INTERVAL / default_time_step(model, args.speed))
    every = round(RECORD_INTERVAL / dt)
    n_steps = math.ceil(DURATION / dt - 1e-9)
    n_samples = n_steps // every + 1
    params = _lean_params(model)
    links, particles = np.arange(N_BEADS - 1), np.arange(N_BEADS)
    fine = integrate(model, velocity, DURATION, dt / 8, 8 * every).link_force[0]
    warm = tuple(out[0] for out in _outputs(1, n_samples, N_BEADS - 1, N_BEADS))

    def direct(module=kernels, record_every=every, outputs=None):
        def run():
            out = outputs
            if out is None:
                out = tuple(o[0] for o in _outputs(1, n_samples, N_BEADS - 1, N_BEADS))
            u, v = np.zeros(N_BEADS), velocity[0].copy()
            status = module._integrate_one(
                u, v, params, dt, n_steps, record_every, links, particles, out
            )
            return out, status

        return run

    contenders = {
        "simulate()": lambda: simulate(model, args.speed, args.speed, duration=DURATION),
        "integrate()": lambda: integrate(model, velocity, DURATION, dt, every),
        "integrate(), one step": lambda: integrate(model, velocity, dt, dt, every),
        "kernel, fresh outputs": direct(),
        "kernel, warm outputs": direct(outputs=warm),
        "kernel, no records": direct(record_every=n_steps, outputs=warm),
    }
    with tempfile.TemporaryDirectory() as folder:
        variants = {label: patched_kernel(Path(folder), *rest) for label, *rest in SCHEMES}
        for label, module in variants.items():
            contenders[label] = direct(module, outputs=warm)
        c_function, how = load_c(folder)
        print(f"C yardstick: {how}")
        if c_function is not None:
            contenders["C"] = lambda: c_run(c_function, velocity[0], args.eta, dt, n_steps, every)
        if args.eta == 0:
            for rtol in args.rtol:
                contenders[f"DOP853 rtol {rtol:.2e}"] = lambda r=rtol: dop853(
                    r, velocity[0], np.arange(n_samples) * RECORD_INTERVAL
                )
        for function in contenders.values():
            function()  # compile
        best = best_times(contenders, args.repeat)
    print(
        f"N = {N_BEADS}, V0 = {args.speed} m/s, eta = {args.eta:.2e} s, dt = {dt:.4e} s, "
        f"{n_steps} steps, {n_samples} samples; CPU ms, best of {args.repeat}; C flags "
        f"{' '.join(C_FLAGS)}"
    )
    conditions.sample("after")
    if conditions.under_load:
        print("UNDER LOAD: the shares below are indicative only")
    total = best["simulate()"]
    runs = {}
    for label in ["kernel, warm outputs", *variants]:
        out, (_, _, refined) = contenders[label]()
        runs[label] = ([a.copy() for a in out], refined)
    converged = runs[CONVERGED][0]
    for label, seconds in best.items():
        line = f"  {label:28s} {seconds * 1e3:7.2f} ms  {seconds / total * 100:5.1f} %"
        if label in runs:
            out, refined = runs[label]
            energy = out[3].sum(axis=1)
            drift = np.abs(energy - energy[0]).max() / energy[0]
            error = np.abs(out[0] - fine).max() / fine.max()
            # The error the scheme adds at the events: distance from the converged one.
            own = np.abs(out[0] - converged[0]).max() / fine.max()
            own_energy = np.abs(energy - converged[3].sum(axis=1)).max() / energy[0]
            line += (
                f"  refined {refined:4d}  drift {drift:.2e}  force error {error:.2e}"
                f"  event error {own:.1e} / {own_energy:.1e}"
            )
        print(line)
    kernel = best["kernel, warm outputs"]
    parts = {
        "simulate(): checks, default step, bead view": total - best["integrate()"],
        "integrate(): wrapper, output allocation": best["integrate()"] - kernel,
        "recording (1 us)": kernel - best["kernel, no records"],
        "contact-event refinement": kernel - best["no refinement"],
    }
    parts["plain steps + event detection"] = total - sum(parts.values())
    print("breakdown of simulate():")
    for label, seconds in parts.items():
        line = f"  {label:45s} {seconds * 1e3:6.2f} ms  {seconds / total * 100:5.1f} %"
        if "C" in best:
            line += f"  {seconds / best['C']:5.2f} x C"
        print(line)
    plain = parts["plain steps + event detection"]
    if "C" in best:
        print(
            f"simulate() / C = {total / best['C']:.2f}; integrate() / C = "
            f"{best['integrate()'] / best['C']:.2f}; plain steps / C = {plain / best['C']:.2f}"
        )
    for label, seconds in best.items():
        if label.startswith("DOP853"):
            print(
                f"{label} / simulate() = {seconds / total:.1f}; / plain steps alone = "
                f"{seconds / plain:.1f} (the ceiling if the wrappers, recording and "
                "refinement cost nothing)"
            )
    if "C" in best:
        c = f"C RK4 ({' '.join(C_FLAGS)}), same run"
        figures = [Figure("simulate() / C", total / best["C"], "x", "the parts below", c)]
        figures += [
            Figure(k, v / best["C"], "x", "its share of simulate()", c) for k, v in parts.items()
        ]
        write_result("kernel_breakdown" + ("_damped" if args.eta else ""), figures, conditions)


if __name__ == "__main__":
    main()
