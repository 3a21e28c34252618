"""Cold compile of the kernels: the first chain.simulate of each kind of model in a fresh
interpreter whose numba cache is empty, and what the compile spends its time on.

Run from the repository root::

    python benchmarks/bench_compile.py                      # best of 3 rounds
    python benchmarks/bench_compile.py --baseline /tmp/k9fb/src --rounds 3

Each round starts, for this tree's ``src`` and each ``--baseline`` source tree (another
commit's ``src``, e.g. from ``git worktree add /tmp/k9fb 9fb9b1b``), interleaved, a
fresh interpreter with ``NUMBA_CACHE_DIR`` set to a new empty folder, which times:

* ``import``: importing chain.physics (numba and the kernels' modules);
* ``elastic``: the first ``simulate`` of the paper's collision (N = 26, 0.3 m/s, 2 ms)
  in an elastic chain: numba's set-up and the elastic kernel's compile;
* ``damped``: then the same with the Kuwabara-Kono time eta = 0.58 us: the second
  kind's compile (0 when both kinds share a kernel);
* ``both``: the two.

Wall and CPU seconds of the interpreter; the best (least) of ``--rounds``. Then one
more fresh interpreter (``--explain``, on by default) prints where this tree's compile
goes: every numba function compiled, in order, with its inclusive seconds (a callee
that is not inlined at the IR level is compiled on its own, inside its caller's type
inference), and the step loop's compile stages (numba's own passes, LLVM's
optimisation and machine-code generation). Not a test: it asserts nothing.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from measure import Conditions, Figure, OtherProcesses, machine, write_result

SRC = Path(__file__).resolve().parents[1] / "src"

#: The child: one cold run, JSON on its last line.
COLD = """
import json, time
t0, c0 = time.perf_counter(), time.process_time()
try:
    from chain.physics.builders import uniform_chain
except ImportError:  # before the builders' own module
    from chain.physics.model import uniform_chain
from chain.physics.simulation import simulate
out = {"import": (time.perf_counter() - t0, time.process_time() - c0)}
for name, eta in (("elastic", 0.0), ("damped", 0.58e-6)):
    t, c = time.perf_counter(), time.process_time()
    simulate(uniform_chain(26, eta=eta), 0.3, 0.3, duration=2e-3)
    out[name] = (time.perf_counter() - t, time.process_time() - c)
print(json.dumps(out))
"""

#: The child of --explain: numba's compile events and the step loop's stage times.
EXPLAIN = """
import time
from numba.core import event
from chain.physics.builders import uniform_chain
from chain.physics.simulation import simulate
from chain.physics import kernels
listener = event.RecordingListener()
event.register("numba:compile", listener)
for eta in (0.0, 0.58e-6):
    t = time.perf_counter()
    simulate(uniform_chain(26, eta=eta), 0.3, 0.3, duration=2e-3)
    print(f"first simulate, eta = {eta:.2e} s: {time.perf_counter() - t:.2f} s wall")
    print("  numba functions compiled (inclusive s, in the order they finished):")
    starts = {}
    for stamp, ev in listener.buffer:
        key = (id(ev.data["dispatcher"]), str(ev.data["args"]))
        if ev.is_start:
            starts[key] = stamp
        else:
            d = ev.data["dispatcher"]
            name = f"{d.py_func.__module__}.{d.__name__}"
            print(f"    {stamp - starts[key]:6.2f}  {name}")
    listener.buffer.clear()
    sig = list(kernels._integrate_part.overloads)[-1]
    meta = kernels._integrate_part.overloads[sig].metadata
    print("  the step loop (_integrate_part), numba's passes (s, callees' compiles included):")
    for times in meta["pipeline_times"].values():
        for name, t in sorted(times.items(), key=lambda kv: -kv[1].run)[:6]:
            print(f"    {t.run:6.2f}  {name}")
    print("  the step loop, LLVM (s; its module holds the inlined callees):")
    for record in meta.get("llvm_pass_timings") or []:
        if not record.name.startswith("Function passes"):
            print(f"    {record.timings.get_total_time():6.2f}  {record.name}")
"""


def cold_run(src: Path, script: str, extra_env: dict | None = None) -> str:
    """``script`` in a fresh interpreter on ``src`` with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_CACHE_DIR": cache}
        env.pop("NUMBA_DISABLE_JIT", None)
        done = subprocess.run(
            [sys.executable, "-c", script],
            capture_output=True,
            text=True,
            env={**env, **(extra_env or {})},
            check=False,
        )
    if done.returncode != 0:
        raise SystemExit(f"{src}: {done.stderr[-2000:]}")
    return done.stdout


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--baseline", type=Path, action="append", default=[])
    parser.add_argument("--no-explain", dest="explain", action="store_false")
    args = parser.parse_args()
    print(machine())
    conditions = Conditions()
    conditions.sample("before")
    trees = {"this tree": SRC, **{str(path): path for path in args.baseline}}
    best = {name: {} for name in trees}
    with OtherProcesses(interval=1.0) as others:
        measure_rounds(args.rounds, trees, best)
    conditions.sample("after")
    report(args, best, conditions, others.share)


def measure_rounds(rounds: int, trees: dict, best: dict) -> None:
    """Best (wall, CPU) s of each tree's cold compiles, ``rounds`` interleaved."""
    for _ in range(rounds):
        for name, src in trees.items():
            figures = json.loads(cold_run(src, COLD).splitlines()[-1])
            figures["both"] = [a + b for a, b in zip(figures["elastic"], figures["damped"])]
            for key, (wall, cpu) in figures.items():
                old = best[name].get(key, (float("inf"), float("inf")))
                best[name][key] = (min(old[0], wall), min(old[1], cpu))


def report(args, best: dict, conditions: Conditions, others: float) -> None:
    """Print the best figures and write benchmarks/results/bench_compile.json."""
    print(f"cold compile, fresh interpreter, empty NUMBA_CACHE_DIR; best of {args.rounds}:")
    for name, figures in best.items():
        print(f"  {name}")
        for key, (wall, cpu) in figures.items():
            print(f"    {key:8s} {wall:6.2f} s wall  {cpu:6.2f} s CPU")
    if conditions.under_load:
        print("UNDER LOAD: the figures above are upper bounds")
    targets = {"elastic": 3.0, "damped": 3.0, "both": 5.0}  # s, on a 2-core Xeon
    figures = [
        Figure(f"cold compile, {key} ({name})", wall, "s",
               "numba's type inference and lowering of the step loop, then LLVM", None,
               f"<= {targets[key]:.0f} s" if name == "this tree" else "",
               conditions.verdict(wall <= targets[key]) if name == "this tree" else "")
        for name, figures in best.items()
        for key, (wall, _) in figures.items() if key in targets
    ]  # fmt: skip
    write_result("bench_compile", figures, conditions, others)
    if args.explain:
        print("\nwhere this tree's compile goes (one more cold run, LLVM pass timings on):")
        print(cold_run(SRC, EXPLAIN, {"NUMBA_LLVM_PASS_TIMINGS": "1"}))


if __name__ == "__main__":
    main()
