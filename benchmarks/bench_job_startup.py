"""What a computed job pays before its first line of work, step by step, in fresh
interpreters: the interpreter itself, Snakemake's script preamble (it unpickles the
job's ``snakemake`` object and imports Snakemake's logging and containers), then the
script's own imports (``_logging`` among them: the store's check of the job's inputs
and its seal, chain.pipeline.run.entries).

Run from the repository root::

    python benchmarks/bench_job_startup.py                 # best of 5 rounds
    python benchmarks/bench_job_startup.py --rounds 9 --scripts delay_fits summary

Each round starts every measurement once, interleaved; the best (least) wall time of
the rounds is kept, and the load average printed before and after. CPU-bound and
noisy: ratios between steps measured in the same rounds are what to read.
"""

from __future__ import annotations

import argparse
import ast
import pickle
import subprocess
import sys
import time
from pathlib import Path

from measure import Conditions, Figure, OtherProcesses, write_result

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ROOT / "workflow" / "scripts"
#: A job of each kind: a small table, the summary, a figure, a simulation.
DEFAULT_SCRIPTS = ("delay_fits", "summary", "fig4_delay_vs_force", "simulate")

#: Snakemake's preamble, as ``snakemake.script.PythonScript`` writes it (9.27).
PREAMBLE = (
    "import sys; import pickle; snakemake = pickle.loads({payload!r}); "
    "from snakemake.logging import logger; from snakemake.iocontainers import Snakemake\n"
)


def payload() -> bytes:
    """A pickled ``snakemake`` object of a typical job (a few named inputs)."""
    from snakemake import iocontainers as io

    inputs = io.InputFiles([f"results/paper/tables/t{i}.csv" for i in range(30)])
    job = io.Snakemake(inputs, io.OutputFiles(["results/paper/tables/out.csv"]), io.Params(),
                       io.Wildcards(), 1, io.ResourceList(), io.Log(["x.log"]),
                       {"run_name": "paper"}, "delay_fits", 0, str(SCRIPTS))  # fmt: skip
    return pickle.dumps(job, protocol=4)


def script_imports(script: Path) -> str:
    """The script's top-level import statements, its folder on the path."""
    tree = ast.parse(script.read_text())
    lines = [ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
    return f"import sys; sys.path.insert(0, {str(script.parent)!r})\n" + "\n".join(lines)


def commands(names) -> dict[str, str]:
    """Measurement name -> Python code run in a fresh interpreter."""
    preamble = PREAMBLE.format(payload=payload())
    code = {"interpreter": "pass", "preamble": preamble}
    for name in names:
        code[f"{name}: preamble + imports"] = preamble + script_imports(SCRIPTS / f"{name}.py")
    return code


def best_times(code: dict[str, str], rounds: int) -> dict[str, float]:
    """Best wall time (s) of ``rounds`` interleaved fresh interpreters per command."""
    best = dict.fromkeys(code, float("inf"))
    for _ in range(rounds):
        for name, text in code.items():
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", text], check=True, cwd=ROOT)
            best[name] = min(best[name], time.perf_counter() - start)
    return best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--scripts", nargs="+", default=list(DEFAULT_SCRIPTS))
    args = parser.parse_args(argv)
    conditions = Conditions()
    code = commands(args.scripts)
    conditions.sample("before")
    with OtherProcesses() as others:
        best = best_times(code, args.rounds)
    conditions.sample("after")
    base = best["interpreter"]
    figures = [Figure("interpreter (python -c pass)", base, "s", "Python's start-up")]
    preamble = best["preamble"] - base
    figures.append(Figure("Snakemake's preamble", preamble, "s",
                          "unpickling the job and importing Snakemake's modules"))  # fmt: skip
    print(f"best of {args.rounds} rounds: interpreter {base:.3f} s, preamble +{preamble:.3f} s")
    for name in args.scripts:
        own = best[f"{name}: preamble + imports"] - best["preamble"]
        print(f"  {name:24s} imports +{own:.3f} s")
        figures.append(Figure(f"{name}: its imports", own, "s", "the packages it uses"))
    write_result("bench_job_startup", figures, conditions, others.share)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
