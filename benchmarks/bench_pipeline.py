"""What a user waits for: the paper run (numba's cache cold, and warm), three what-ifs
and the tests, each against a yardstick measured in the same rounds.

Every round works in a fresh copy of the checkout (workflow_runs: the files git tracks,
no numba cache, no results, no result store; LAMMPS hidden unless ``--lammps``), whose
``src`` the jobs import, and runs in order::

    cold        snakemake --cores 2               numba's cache empty
    warm        the same, results/ and .snakemake/ removed (the store with them),
                numba's cache kept
    brass       snakemake --cores 2 --configfile whatif/brass.yaml     after the paper run
    analysis    an overlay: run_name bench_analysis, analysis: {main_estimator: peak}
    figure      an overlay: run_name bench_figure, figures: {representative_force_N: 100}

The **yardstick** is the paper run of :data:`BASELINE_COMMIT` in a fresh copy of that
commit, on the same interpreter, cold and then warm as above, in every round. The
targets are ratios: the cold run to the yardstick's cold run, every other scenario to
its warm run (:data:`TARGETS`). Rounds are interleaved (each round runs every command
once, so that load hits all of them alike) and the best of each is kept, with the load
average before and after each round, and a verdict that is never "met" when other
processes took more than 5 % of the machine's CPU during the command or its yardstick
(measure.OtherProcesses). Then the README's test command runs once in the last copy
(``--no-tests`` skips it)::

    python benchmarks/bench_pipeline.py                  # 3 rounds and the tests
    python benchmarks/bench_pipeline.py --repeat 1 --no-tests --keep /tmp/bench

A scenario's jobs are those Snakemake started (its ``rule`` lines); those a
``--forceall`` dry run lists beyond them were not started: their result was present in
the store. A what-if's dry run must list exactly the jobs it then starts, and the
analysis and figure what-ifs must start no simulation (the rules whose scripts reach the
integrator or LAMMPS: :func:`simulation_rules`). The paper run's jobs are also summed
from Snakemake's benchmark files, which the run folder keeps
(``results/paper/benchmarks/**/*.tsv`` of the warm run: wall ``s``, and ``cpu_time``
as Snakemake last sampled it, a lower bound), with a table per rule. The best times,
their ratios and verdicts go to benchmarks/results/ (``measure.write_result``).
"""

from __future__ import annotations

import argparse
import ast
import re
import shutil
import sys
import tempfile
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

sys.path.insert(0, str(Path(__file__).parent))
from measure import UNDER_LOAD, Conditions, Figure, write_result
from workflow_runs import (
    Timed,
    copy_commit,
    copy_tree,
    environment,
    fresh,
    planned,
    run,
    run_name,
    snakemake,
    started,
)

#: (name, snakemake arguments, overlay written into the copy or None), in order.
SCENARIOS = (
    ("cold", [], None),
    ("warm", [], None),
    ("brass", ["--configfile", "whatif/brass.yaml"], None),
    ("analysis", ["--configfile", "bench_analysis.yaml"],
     "run_name: bench_analysis\nanalysis: {main_estimator: peak}\n"),
    ("figure", ["--configfile", "bench_figure.yaml"],
     "run_name: bench_figure\nfigures: {representative_force_N: 100}\n"),
)  # fmt: skip
#: The what-ifs: each runs after the paper run, its dry run checked against it.
WHAT_IFS = ("brass", "analysis", "figure")
#: The yardstick's commit: each job its own process, no reuse across runs.
BASELINE_COMMIT = "9fb9b1b"
#: Scenario -> (the yardstick's run it is a ratio to, the largest ratio).
TARGETS = {
    "cold": ("cold", 0.50),
    "warm": ("warm", 0.45),
    "brass": ("warm", 0.30),
    "analysis": ("warm", 0.12),
    "figure": ("warm", 0.10),
}
#: The most the warm paper run's jobs may take in all (their benchmark files), s.
SUMMED_TARGET_S = 55.0
#: What the integrators are: a rule whose script reaches one of these simulates.
INTEGRATORS = frozenset(
    {
        "chain.physics.integrator.integrate",
        "chain.physics.integrator.integrate_many",
        "chain.physics.lammps_engine.run_granular_chain",
    }
)
#: What bounds each scenario's time (benchmarks/README.md has the measurements).
BOUNDS = {
    "yardstick": "the baseline commit's jobs, each in its own process",
    "cold": "CPU: numba's cold compile on the critical path, then the jobs' CPU on 2 cores",
    "warm": "CPU: every job's work and start-up on 2 cores, nothing compiled",
    "brass": "CPU: the new material's simulations and everything downstream",
    "analysis": "CPU: the fits and figures downstream of the estimator, no simulation",
    "figure": "CPU: Fig. 3 and the space-time figure drawn again, the summary, the article",
    "jobs": "the jobs' own work and start-up (imports), each in its own process",
    "tests": "CPU: the suite's Snakemake runs and the kernel tests' cold compiles",
}
#: Why a what-if starts the simulation jobs it starts.
BOUND_SIMULATIONS = {
    "analysis": "no simulation's input changes",
    "figure": "no simulation's input changes: Fig. 3 and the space-time figure read "
    "what simulate recorded (every bead's felt force, the pooled field)",
}


# ---- the rules that simulate, from their scripts --------------------------------------


def _module_files(src: Path) -> dict[str, Path]:
    modules = {}
    for path in src.rglob("*.py"):
        parts = path.relative_to(src).with_suffix("").parts
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def _imported(tree: ast.AST, module: str, package: str) -> dict[str, str]:
    """Name bound by an import anywhere in ``tree`` -> the dotted name it stands for."""
    names = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                names[alias.asname or alias.name.split(".")[0]] = (
                    alias.name if alias.asname else alias.name.split(".")[0]
                )
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(parts + ([node.module] if node.module else []))
            for alias in node.names:
                names[alias.asname or alias.name] = f"{base}.{alias.name}"
    return names


def _resolve(expression, module, defined, imported, modules) -> str | None:
    """The dotted name ``expression`` (a name or ``name.attribute...``) refers to in
    ``module``: one of its definitions, or what it imported (None: neither)."""
    attributes = []
    while isinstance(expression, ast.Attribute):
        attributes.append(expression.attr)
        expression = expression.value
    if not isinstance(expression, ast.Name):
        return None
    if expression.id in defined:
        return f"{module}.{expression.id}"
    name = imported.get(expression.id)
    for attribute in reversed(attributes if name else []):
        if name not in modules:
            break
        name = f"{name}.{attribute}"  # module.attribute: a name of that module
    return name


def uses(src: Path) -> dict[str, set[str]]:
    """Dotted name of each module-level definition (function, class, assignment) and
    import of the package under ``src`` -> the dotted names its code refers to."""
    modules, graph = _module_files(src), {}
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        imported = _imported(tree, module, package)
        defined = {}
        for node in tree.body:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                defined[node.name] = node
            elif isinstance(node, ast.Assign | ast.AnnAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                defined.update({t.id: node for t in targets if isinstance(t, ast.Name)})

        for name, node in defined.items():
            found = {
                _resolve(n, module, defined, imported, modules)
                for n in ast.walk(node)
                if isinstance(n, ast.Name | ast.Attribute)
            }
            graph[f"{module}.{name}"] = found - {None}
        graph[module] = {f"{module}.{name}" for name in defined}
        for name, target in imported.items():  # a name a module imports, re-exported
            graph.setdefault(f"{module}.{name}", set()).add(target)
    return graph


def simulation_rules(tree: Path) -> tuple[str, ...]:
    """The rules of ``tree``'s workflow whose script reaches an integrator
    (:data:`INTEGRATORS`) through the names it imports from the library (``src``):
    the rules that simulate."""
    graph = uses(tree / "src")
    scripts = {}
    for rules in sorted((tree / "workflow" / "rules").glob("*.smk")):
        text = rules.read_text(encoding="utf-8")
        for rule, body in re.findall(r"^rule (\w+):\n((?:[ \t]+.*\n|\n)*)", text, re.M):
            found = re.search(r"script:\s*\n?\s*\"([^\"]+)\"", body)
            if found:
                scripts[rule] = (rules.parent / found.group(1)).resolve()
    simulating = []
    for rule, script in sorted(scripts.items()):
        names = set()
        for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("chain"):
                names |= {f"{node.module}.{alias.name}" for alias in node.names}
        seen, todo = set(), list(names)
        while todo:
            name = todo.pop()
            if name not in seen:
                seen.add(name)
                todo += graph.get(name, ())
        if seen & INTEGRATORS:
            simulating.append(rule)
    if not simulating:
        raise SystemExit(f"no rule of {tree / 'workflow/rules'} reaches an integrator")
    return tuple(simulating)


# ---- the runs -------------------------------------------------------------------------


@dataclass
class Outcome:
    """A scenario's run: its time, the jobs it started, those its ``--forceall`` dry
    run lists (what the targets need), those its dry run listed (what-ifs only) and the
    paper run's benchmark files (warm only)."""

    timed: Timed
    started: Counter
    needed: Counter
    listed: Counter | None = None
    benchmarks: pd.DataFrame | None = None

    @property
    def not_started(self) -> int:
        return max(sum(self.needed.values()) - sum(self.started.values()), 0)


def benchmark_files(folder: Path) -> pd.DataFrame:
    """One row per Snakemake benchmark file under ``folder`` (``<rule>.tsv`` or
    ``<rule>/<label>.tsv``): rule, wall s (``s``), CPU s (``cpu_time``, NaN without)."""
    rows = []
    for path in sorted(folder.rglob("*.tsv")):
        table = pd.read_csv(path, sep="\t")
        rule = path.relative_to(folder).parts[0].removesuffix(".tsv")
        cpu = table["cpu_time"].sum() if "cpu_time" in table else float("nan")
        rows.append({"rule": rule, "wall_s": table["s"].sum(), "cpu_s": cpu})
    return pd.DataFrame(rows, columns=["rule", "wall_s", "cpu_s"])


def per_rule(files: pd.DataFrame) -> pd.DataFrame:
    """Per rule of a run's benchmark files: jobs, summed wall s and CPU s."""
    table = files.groupby("rule").agg(
        jobs=("rule", "size"), wall_s=("wall_s", "sum"), cpu_s=("cpu_s", "sum")
    )
    table = table.sort_values("wall_s", ascending=False)
    table.loc["(all)"] = [table["jobs"].sum(), table["wall_s"].sum(), table["cpu_s"].sum()]
    return table


def yardstick(work: Path, cores: int, env_of) -> dict:
    """The paper run of :data:`BASELINE_COMMIT` in a fresh copy of it, cold then warm."""
    copy_commit(BASELINE_COMMIT, work)
    env, timings = env_of(work), {}
    for name in ("cold", "warm"):
        if name == "warm":
            fresh(work)
        timings[name], _ = run(snakemake(cores), work, env)
        print(f"  yardstick {name} ({BASELINE_COMMIT} paper run): {timings[name].wall:.1f} s, "
              f"other processes {timings[name].others:.1%} of the CPU", flush=True)  # fmt: skip
    return timings


def one_round(work: Path, cores: int, commit: str | None, env_of) -> dict[str, Outcome]:
    """Every scenario once, in order, in a fresh copy: name -> its outcome."""
    copy_tree(work, commit)
    env, outcomes = env_of(work), {}
    for name, args, overlay in SCENARIOS:
        if overlay:
            (work / f"bench_{name}.yaml").write_text(overlay)
        if name == "warm":
            fresh(work)
        command = snakemake(cores, *args)
        listed = planned(run([*command, "-n"], work, env)[1]) if name in WHAT_IFS else None
        timed, printed = run(command, work, env)
        needed = planned(run([*command, "-n", "--forceall"], work, env)[1])
        outcome = Outcome(timed, started(printed), needed, listed)
        if name == "warm":
            folder = work / "results" / run_name(work) / "benchmarks"
            outcome.benchmarks = benchmark_files(folder)
        outcomes[name] = outcome
        print(f"  {name}: {timed.wall:.1f} s, {sum(outcome.started.values())} jobs started, "
              f"{outcome.not_started} not started (result present), other processes "
              f"{timed.others:.1%} of the CPU", flush=True)  # fmt: skip
    return outcomes


# ---- the figures ----------------------------------------------------------------------


def verdict(met: bool, *timed: Timed) -> str:
    """Met or not; never "met" when other processes took more than MAX_OTHER_SHARE of
    the CPU during any of the commands ``timed``."""
    loaded = [t for t in timed if not t.quiet]
    if loaded:
        return f"{UNDER_LOAD} (others {max(t.others for t in loaded):.0%})"
    return "met" if met else "not met"


def summarise(rounds: list[dict], yardsticks: list[dict], simulations) -> list[Figure]:
    """The best round of each scenario, and its ratio to the best yardstick run it is
    judged against; returns them as the figures of the results file."""
    figures = []
    print(f"\nbest of {len(rounds)} interleaved round(s), --cores as given:")
    best = {k: min((y[k] for y in yardsticks), key=lambda t: t.wall) for k in ("cold", "warm")}
    for kind, timed in best.items():
        print(f"  yardstick {kind}: {timed.wall:6.1f} s ({BASELINE_COMMIT}'s paper run)")
        figures.append(Figure(f"yardstick, {kind}", timed.wall, "s", BOUNDS["yardstick"]))
    for name, _, _ in SCENARIOS:
        outcome = min((r[name] for r in rounds), key=lambda o: o.timed.wall)
        against, limit = TARGETS[name]
        ratio = outcome.timed.wall / best[against].wall
        judged = verdict(ratio <= limit, outcome.timed, best[against])
        jobs, rules = sum(outcome.started.values()), sorted(outcome.started)
        shown = ", ".join(rules) if len(rules) <= 6 else f"{len(rules)} rules"
        print(f"  {name:9s} {outcome.timed.wall:6.1f} s  {ratio:6.3f} x the yardstick's "
              f"{against} run (target <= {limit}: {judged}); {jobs} jobs started ({shown}), "
              f"{outcome.not_started} not started")  # fmt: skip
        figures.append(Figure(f"{name} ({jobs} jobs started, {outcome.not_started} not)",
                              outcome.timed.wall, "s", BOUNDS[name]))  # fmt: skip
        figures.append(Figure(f"{name} / yardstick {against}", ratio, "x", BOUNDS[name],
                              f"the yardstick: {BASELINE_COMMIT}'s {against} paper run, best "
                              "round", f"<= {limit}", judged))  # fmt: skip
    warm = min((r["warm"] for r in rounds), key=lambda o: o.benchmarks["wall_s"].sum())
    summed, cpu = warm.benchmarks["wall_s"].sum(), warm.benchmarks["cpu_s"].sum()
    jobs = len(warm.benchmarks)
    judged = verdict(summed <= SUMMED_TARGET_S, warm.timed)
    print(f"  the paper run's {jobs} jobs, summed from their benchmark files: {summed:.1f} s "
          f"wall (target <= {SUMMED_TARGET_S:g} s: {judged}), {cpu:.1f} s CPU")  # fmt: skip
    figures.append(Figure(f"the paper run's jobs, summed wall time from its benchmark files "
                          f"({jobs} jobs)", summed, "s", BOUNDS["jobs"], None,
                          f"<= {SUMMED_TARGET_S:g} s", judged))  # fmt: skip
    for name in ("analysis", "figure"):
        outcomes = [r[name] for r in rounds]
        rules = {rule for o in outcomes for rule in [*o.started, *o.listed]}
        simulated = sorted(rules & set(simulations))
        same = all(o.started == o.listed for o in outcomes)
        print(
            f"  {name} what-if: simulation jobs started or listed by its dry run: "
            f"{', '.join(simulated) or 'none'}; dry run lists what it starts: {same}"
        )
        count = max(sum(max(o.started[r], o.listed[r]) for r in simulated) for o in outcomes)
        figures.append(Figure(f"{name} what-if, simulation jobs started or listed (its dry "
                              f"run lists {'what' if same else 'not what'} it starts)", count,
                              "jobs", BOUND_SIMULATIONS[name], None, "0",
                              "met" if not simulated and same else "not met"))  # fmt: skip
    for name in WHAT_IFS:
        for k, outcome in enumerate(rounds):
            if outcome[name].started != outcome[name].listed:
                print(f"  {name}, round {k + 1}: the dry run listed "
                      f"{dict(outcome[name].listed)}, the run started "
                      f"{dict(outcome[name].started)}")  # fmt: skip
    return figures


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=3, help="interleaved rounds")
    parser.add_argument("--no-tests", action="store_true", help="skip the test suite")
    parser.add_argument("--keep", type=Path, help="work under this folder and keep it")
    parser.add_argument("--commit", help="measure this commit (default: the work tree)")
    parser.add_argument("--lammps", action="store_true", help="let the runs use LAMMPS")
    args = parser.parse_args(argv)
    base = args.keep or Path(tempfile.mkdtemp(prefix="bench_pipeline_"))
    conditions = Conditions()
    rounds, yardsticks = [], []
    env_of = lambda work: environment(work, lammps=args.lammps)  # noqa: E731
    try:
        for k in range(args.repeat):
            for folder in (f"round{k}", f"yardstick{k}"):
                shutil.rmtree(base / folder, ignore_errors=True)
            conditions.sample(f"before round {k + 1}")
            yardsticks.append(yardstick(base / f"yardstick{k}", args.cores, env_of))
            rounds.append(one_round(base / f"round{k}", args.cores, args.commit, env_of))
            conditions.sample(f"after round {k + 1}")
        simulations = simulation_rules(base / "round0")
        print(f"\nrules that simulate (their scripts reach an integrator): "
              f"{', '.join(simulations)}")  # fmt: skip
        warm = min((r["warm"] for r in rounds), key=lambda o: o.benchmarks["wall_s"].sum())
        print("\nthe warm paper run's jobs per rule, from its benchmark files (best round; CPU "
              "as Snakemake last sampled it, 1 s then every 30 s: a lower bound):")  # fmt: skip
        print(per_rule(warm.benchmarks).to_string(float_format=lambda v: f"{v:.1f}"))
        figures = summarise(rounds, yardsticks, simulations)
        commands = [t for y in yardsticks for t in y.values()]
        commands += [o.timed for r in rounds for o in r.values()]
        if not args.no_tests:
            conditions.sample("before the tests")
            tests = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
            last = base / f"round{args.repeat - 1}"
            timed, printed = run(tests, last, environment(last, lammps=True))
            conditions.sample("after the tests")
            closing = printed.strip().splitlines()[-1]
            print(f"  tests     {timed.wall:6.1f} s  ({closing})")
            figures.append(Figure(f"tests ({closing})", timed.wall, "s", BOUNDS["tests"]))
            commands.append(timed)
        # Other processes' share over every timed command, weighted by its time.
        others = sum(t.others * t.wall for t in commands) / sum(t.wall for t in commands)
        write_result("bench_pipeline", figures, conditions, others, own_load=True)
    finally:
        if not args.keep:
            shutil.rmtree(base, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
