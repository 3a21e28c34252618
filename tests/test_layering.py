"""The library's layering, read off the import statements (``ast``): imports run
downhill only, so that physics can be read without tables, the analysis without
figures, and the report without an integrator.

    pipeline, cli          (config keys, results/, the command line); the pipeline in
                           rooms: config <- plan <- run, provenance beside them
    studies | report       (side by side, no arrow between them)
      studies              -> physics, apparatus, analysis (simulate and analyse in-process)
      report               -> analysis, physics.theory/materials
    apparatus | analysis   (side by side, no arrow between them)
    physics                -> errors only
    errors, atomic, csv_text, traces, labels, sampling, _lazy
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "chain"
BOTTOM = {
    "chain",
    "chain._lazy",
    "chain.errors",
    "chain.atomic",
    "chain.csv_text",
    "chain.traces",
    "chain.labels",
    "chain.sampling",
}

#: Wing -> the chain modules or wings (prefixes) it may import.
ALLOWED = {
    "bottom": BOTTOM,
    "physics": {"chain", "chain._lazy", "chain.errors", "chain.physics"},
    "apparatus": BOTTOM | {"chain.physics", "chain.apparatus"},
    "analysis": BOTTOM | {"chain.analysis"},
    "report": BOTTOM
    | {"chain.report", "chain.analysis", "chain.physics.theory", "chain.physics.materials"},
    "studies": BOTTOM | {"chain.studies", "chain.physics", "chain.apparatus", "chain.analysis"},
    "pipeline": BOTTOM
    | {"chain.pipeline", "chain.studies", "chain.physics", "chain.apparatus", "chain.analysis"},
    "cli": BOTTOM
    | {"chain.physics", "chain.apparatus", "chain.analysis", "chain.studies", "chain.pipeline"},
}

#: Wing -> third-party packages it must not import.
FORBIDDEN = {
    "bottom": {"matplotlib", "numba", "scipy", "yaml"},
    "physics": {"pandas", "matplotlib", "yaml"},
    "apparatus": {"matplotlib"},
    "analysis": {"matplotlib", "numba"},
    "report": {"numba"},
    "studies": {"matplotlib"},
    "pipeline": {"matplotlib"},
    "cli": set(),
}


def wing(module: str) -> str:
    parts = module.split(".")
    if len(parts) > 1 and parts[1] in ALLOWED:
        return parts[1]
    return "bottom"


def modules() -> dict[str, Path]:
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def imports(path: Path) -> set[str]:
    """Absolute names of every module imported anywhere in ``path`` (``from a import b``
    gives ``a`` and ``a.b``, as b may be a submodule)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module)
            names |= {f"{node.module}.{alias.name}" for alias in node.names}
    return names


def allowed(importer: str, imported: str) -> bool:
    """May a module of ``importer``'s wing import ``imported``? (``chain`` itself is
    allowed by exact name only; a wing allows its submodules.)"""
    return any(
        imported == prefix or (prefix != "chain" and imported.startswith(prefix + "."))
        for prefix in ALLOWED[wing(importer)]
    )


MODULES = modules()


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_run_downhill(module):
    wrong = sorted(
        name
        for name in imports(MODULES[module])
        if name.startswith("chain") and name in MODULES and not allowed(module, name)
    )
    assert not wrong, f"{module} ({wing(module)}) imports {wrong} against the layering"


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_forbidden_third_party_imports(module):
    top = {name.split(".")[0] for name in imports(MODULES[module])}
    wrong = sorted(top & (FORBIDDEN[wing(module)] | {"snakemake"}))
    assert not wrong, f"{module} ({wing(module)}) imports {wrong}"


#: The pipeline's rooms -> the rooms each may import: one way, config <- plan <- run,
#: provenance beside them (run states the versions of what it stores).
ROOMS = {
    "config": set(),
    "provenance": set(),
    "plan": {"config"},
    "run": {"config", "plan", "provenance"},
}


def room(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[:2] == ["chain", "pipeline"] else None


@pytest.mark.parametrize("module", sorted(m for m in MODULES if room(m)))
def test_the_pipelines_rooms_import_one_way(module):
    assert set(ROOMS) == {p.name for p in (PACKAGE / "pipeline").iterdir() if p.is_dir()
                          and p.name != "__pycache__"}  # fmt: skip
    wrong = sorted(
        name
        for name in imports(MODULES[module])
        if room(name) and room(name) != room(module) and room(name) not in ROOMS[room(module)]
    )
    assert not wrong, f"{module} ({room(module)}) imports {wrong}: the rooms run one way"


def test_the_check_catches_an_uphill_import(tmp_path):
    """The test itself: physics importing the report, or pandas, is caught."""
    source = tmp_path / "bad.py"
    source.write_text("import pandas\nfrom chain.report.numbers.summary import build_summary\n")
    names = imports(source)
    assert not allowed("chain.physics.model", "chain.report.numbers.summary")
    assert "chain.report.numbers.summary" in names and "pandas" in {n.split(".")[0] for n in names}
    assert allowed("chain.report.figures.fig4_delay_vs_force", "chain.analysis.rows")
    assert not allowed("chain.report.figures.fig4_delay_vs_force", "chain.physics.integrator")
    assert not allowed("chain.analysis.ssw", "chain.apparatus.virtual")
    assert allowed("chain.pipeline.config.check", "chain.studies.ablation")
    assert not allowed("chain.studies.ablation", "chain.pipeline.config.virtual")
    assert not allowed("chain.studies.sweep", "chain.report.fig_c_vs_N")


def test_scripts_import_concrete_modules():
    """Workflow scripts import from the module that defines a name, never the lazy
    ``chain`` package itself: rule inputs are read off these imports."""
    scripts = Path(__file__).resolve().parents[1] / "workflow" / "scripts"
    wrong = [
        path.name
        for path in sorted(scripts.glob("*.py"))
        for node in ast.walk(ast.parse(path.read_text()))
        if isinstance(node, ast.ImportFrom) and node.module in ("chain", "chain.physics")
    ]
    assert not wrong, wrong


def import_graph() -> dict[str, set[str]]:
    """Module -> the chain modules it imports (anywhere in the file, deferred imports
    included: a deferred import only hides a cycle)."""
    return {
        module: {name for name in imports(path) if name in MODULES and name != module}
        for module, path in MODULES.items()
    }


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import cycles of ``graph``: one per strongly connected component of more than
    one module (Tarjan's algorithm), its modules sorted."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in sorted(graph.get(node, ())):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def test_no_import_cycles():
    """No two chain modules import each other, directly or round a loop."""
    assert cycles(import_graph()) == []


def test_the_cycle_check_finds_a_loop():
    """The test itself: a three-module loop is found, a chain of imports is not."""
    loop = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert cycles(loop) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


#: Inside the report: the text formats the numbers, the figures draw the tables; the
#: numbers import neither, and printed/naming (shared by all three) import none of them.
REPORT_ALLOWED = {
    "numbers": {"numbers"},
    "figures": {"figures", "numbers"},
    "text": {"text", "numbers"},
    "shared": set(),
}


def report_part(module: str) -> str:
    parts = module.split(".")
    return parts[2] if len(parts) > 3 and parts[2] in REPORT_ALLOWED else "shared"


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("chain.report.")))
def test_report_parts_import_downhill(module):
    """text -> numbers <- figures; chain.report.printed and .naming under all three."""
    own = report_part(module)
    wrong = sorted(
        name
        for name in imports(MODULES[module])
        if name.startswith("chain.report.")
        and name in MODULES
        and report_part(name) != "shared"
        and report_part(name) not in REPORT_ALLOWED[own]
    )
    assert not wrong, f"{module} ({own}) imports {wrong}"


def test_report_package_inits_import_nothing():
    """A figure's rule depends on the code its script imports (chain.pipeline.plan.code),
    with the __init__ files on the way: they must not pull in the whole report."""
    for name in (
        "chain.report",
        *(f"chain.report.{part}" for part in ("figures", "numbers", "text")),
    ):
        assert not {n for n in imports(MODULES[name]) if n.startswith("chain")}, name


def test_the_plan_is_in_parts_none_too_big():
    """Each study and concern of the run plan is a module of its own: none over 300 lines,
    no class over 20 methods (RunPlan composes the parts)."""
    for path in sorted((PACKAGE / "pipeline" / "plan").glob("*.py")):
        text = path.read_text()
        assert len(text.splitlines()) <= 300, path.name
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                methods = [b for b in node.body if isinstance(b, ast.FunctionDef)]
                assert len(methods) <= 20, f"{path.name}: {node.name}"


WORKFLOW = PACKAGE.parents[1] / "workflow"


def test_rule_files_share_names_through_common_only():
    """A name defined at the top of a rule file other than common.smk is used in that
    file only: the includes' order makes nothing work by accident."""
    files = {path: path.read_text() for path in (WORKFLOW / "rules").glob("*.smk")}
    files[PACKAGE.parents[1] / "Snakefile"] = (PACKAGE.parents[1] / "Snakefile").read_text()
    for path, text in files.items():
        if path.name == "common.smk":
            continue
        defined = re.findall(r"^(?:def\s+(\w+)|(\w+)\s*=)", text, re.M)
        for name in {a or b for a, b in defined}:
            users = [p.name for p, t in files.items() if p != path and re.search(rf"\b{name}\b", t)]
            assert not users, f"{name} of {path.name} used in {users}"


def test_no_private_name_of_snakemake_is_read():
    """Scripts are plain Snakemake scripts: nothing reads how Snakemake runs them."""
    for root in (PACKAGE, WORKFLOW):
        for path in root.rglob("*.py"):
            assert "__real_file__" not in path.read_text(), path
