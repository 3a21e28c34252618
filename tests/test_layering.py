"""The library's layering, read off the import statements (``ast``): imports run
downhill only, so that physics can be read without tables, the analysis without
figures, and the report without an integrator.

    pipeline, cli          (config keys, results/, the command line); the pipeline in
                           rooms: config <- plan <- run, provenance beside them
    studies | report       (side by side, no arrow between them)
      studies              -> physics, apparatus, analysis (simulate and analyse in-process)
      report               -> analysis, physics.theory/materials
    apparatus | analysis   (side by side, no arrow between them)
    physics                -> errors, trust only
    errors, trust, atomic, csv_text, traces, labels, sampling, _lazy
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
    "chain.trust",
    "chain.atomic",
    "chain.csv_text",
    "chain.traces",
    "chain.labels",
    "chain.sampling",
}

#: Wing -> the chain modules or wings (prefixes) it may import.
ALLOWED = {
    "bottom": BOTTOM,
    "physics": {"chain", "chain._lazy", "chain.errors", "chain.trust", "chain.physics"},
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


CHECKOUT = PACKAGE.parents[1]
WORKFLOW = CHECKOUT / "workflow"
SNAKEFILE = CHECKOUT / "Snakefile"


def included_rule_files() -> list[Path]:
    """The rule files, in the order the Snakefile includes them."""
    names = re.findall(r'^include:\s*"([^"]+)"', SNAKEFILE.read_text(), re.M)
    return [CHECKOUT / name for name in names]


def compiled(path: Path) -> ast.Module:
    """A Snakefile or rule file as Snakemake compiles it to Python (its own parser)."""
    from types import SimpleNamespace

    from snakemake.parser import parse
    from snakemake.sourcecache import LocalSourceFile

    def open_source(source, mode="r"):
        return open(source.get_path_or_uri(secret_free=True), mode)

    reader = SimpleNamespace(sourcecache=SimpleNamespace(open=open_source))
    code, _ = parse(LocalSourceFile(str(path)), reader, {})
    return ast.parse(code, filename=str(path))


def bound(tree: ast.AST) -> set[str]:
    """Every name ``tree`` binds, in any scope: assignments, loop and comprehension
    targets, imports, definitions, arguments."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.ExceptHandler) and node.name:
            names.add(node.name)
    return names


def top_level(tree: ast.Module) -> set[str]:
    """The names a file defines for the files included after it: those bound at module
    level (in its top-level blocks too), but the functions Snakemake makes of rules."""
    names = set()
    todo = list(tree.body)
    while todo:
        node = todo.pop()
        if isinstance(node, ast.For | ast.If | ast.While | ast.With | ast.Try):
            todo += [*node.body, *node.orelse] if hasattr(node, "orelse") else node.body
            targets = [node.target] if isinstance(node, ast.For) else []
        elif isinstance(node, ast.Assign | ast.AnnAssign | ast.AugAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        else:
            targets = []
        names |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
        if isinstance(node, ast.FunctionDef | ast.ClassDef) and not node.name.startswith("__"):
            names.add(node.name)
        elif isinstance(node, ast.Import | ast.ImportFrom):
            names |= {(a.asname or a.name).split(".")[0] for a in node.names}
    return names


def snakemake_globals() -> set[str]:
    """What Snakemake gives every Snakefile and rule file besides Python's builtins:
    its workflow module's names and those it registers (workflow, rules, config, ...)."""
    import builtins

    import snakemake.api  # (snakemake.workflow imports itself through it)
    import snakemake.ioflags
    import snakemake.ioutils
    import snakemake.workflow

    names = dict(vars(snakemake.workflow))
    snakemake.ioutils.register_in_globals(names)
    snakemake.ioflags.register_in_globals(names)
    extra = {"workflow", "rules", "checkpoints", "scatter", "gather", "storage", "config"}
    return set(names) | set(dir(builtins)) | extra | {"shell", "pep", "access", "from_queue"}


def test_rule_files_use_names_of_common_the_snakefile_or_files_before_them():
    """A rule file reads only names it defines, Snakemake's, the Snakefile's imports, and
    those of the rule files included before it (common.smk first): the include order
    is the one dependency between them, and it is written in the Snakefile."""
    files = included_rule_files()
    assert files[0].name == "common.smk" and len(files) > 5, files
    assert {p.name for p in files} == {p.name for p in (WORKFLOW / "rules").glob("*.smk")}
    snakefile = compiled(SNAKEFILE)
    known = snakemake_globals() | {
        (a.asname or a.name).split(".")[0]
        for node in snakefile.body
        if isinstance(node, ast.Import | ast.ImportFrom)
        for a in node.names
    }
    for path in files:
        tree = compiled(path)
        read = {
            n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
        }
        unknown = sorted(read - bound(tree) - known)
        assert not unknown, f"{path.name} reads {unknown}, defined in no file included before it"
        known |= top_level(tree)


def test_the_name_check_catches_a_name_of_a_later_file(tmp_path):
    """The test itself: a name read before the file that defines it is included."""
    early, late = tmp_path / "early.smk", tmp_path / "late.smk"
    early.write_text("X = LATER + 1\n\nrule a:\n    output:\n        f'{X}'\n")
    late.write_text("LATER = 1\n")
    tree = compiled(early)
    read = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
    assert read - bound(tree) - snakemake_globals() == {"LATER"}
    assert top_level(compiled(late)) == {"LATER"} and "X" in top_level(tree)


def workflow_files() -> dict[Path, str]:
    """The Snakefile and the rule files: path -> text."""
    return {
        path: path.read_text() for path in [SNAKEFILE, *sorted((WORKFLOW / "rules").glob("*.smk"))]
    }


def test_every_rule_is_written_out():
    """No rule is made in a loop or under a condition (a ``rule`` keyword at the start
    of its line, with a name, and no ``name:`` directive), and no script path is a
    pattern: a reader finds each rule, and its script, by its name."""
    for path, text in workflow_files().items():
        assert not re.search(r"^[ \t]+rule\b", text, re.M), f"{path.name}: a rule inside a block"
        assert not re.search(r"^rule\s*:", text, re.M), f"{path.name}: a rule without a name"
        assert not re.search(r"^    name\s*:", text, re.M), f"{path.name}: a name: directive"
        for script in re.findall(r"^\s+script:\s*\n?\s*(.+)$", text, re.M):
            assert re.fullmatch(r'"[^"{}]+\.py"', script.strip()), f"{path.name}: {script}"


@pytest.mark.workflow
def test_every_rule_snakemake_lists_is_written_as_a_rule(tmp_path):
    """``snakemake --list-rules`` (the paper config, in a folder of its own) lists
    exactly the rules written as ``rule <name>:`` in the Snakefile and workflow/rules."""
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "--snakefile", str(SNAKEFILE), "--directory",
         str(tmp_path), "--configfile", str(CHECKOUT / "config.yaml"), "--list-rules"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    listed = set(result.stdout.split())
    written = {name for text in workflow_files().values()
               for name in re.findall(r"^rule (\w+):", text, re.M)}  # fmt: skip
    assert listed == written and {"simulate", "pulses", "run_folder", "all"} <= listed


#: The one module that replaces private methods of Snakemake's scheduler, on the release
#: it was written for only (tests/test_snakemake_patches.py pins that release).
PATCHES = PACKAGE / "pipeline" / "run" / "snakemake_patches.py"

#: Reading a private attribute of a Snakemake object: the workflow, its rules, a script's
#: ``snakemake``, a rule proxy, the scheduler, the DAG, a job.
PRIVATE = re.compile(
    r"\b(?:workflow|rules|checkpoints|snakemake|proxy|rule|scheduler|dag|job)"
    r"(?:\.\w+)*\._(?!_)\w*"
)


def test_no_private_name_of_snakemake_is_read():
    """Scripts are plain Snakemake scripts and rule files read Snakemake's public names:
    nothing in workflow/ reads an attribute whose name starts with ``_``, nothing in
    src/ reads one of a Snakemake object (but :data:`PATCHES`), and nothing reads
    ``__real_file__``."""
    for path, text in workflow_files().items():
        assert not re.search(r"\.\_(?!_)\w", text), path
    for path in sorted(WORKFLOW.rglob("*.py")):
        assert not re.search(r"\.\_(?!_)\w", path.read_text()), path
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text()
        assert "__real_file__" not in text, path
        if path != PATCHES:
            assert not PRIVATE.search(text), (path, PRIVATE.search(text)[0])
    assert PRIVATE.search("x = workflow._executor_plugin") and PRIVATE.search("job._x")
    assert not PRIVATE.search("workflow.dryrun") and not PRIVATE.search("self._firsts")


def lines(path: Path) -> int:
    return len(path.read_text().splitlines())


def test_the_workflows_shared_code_stays_small():
    """common.smk at most 150 lines, the pipeline's run room (store, recipes, run folder)
    at most 800, and at most four modules of the library over 400."""
    assert lines(WORKFLOW / "rules" / "common.smk") <= 150
    run = {p.name: lines(p) for p in sorted((PACKAGE / "pipeline" / "run").glob("*.py"))}
    assert sum(run.values()) <= 800, f"src/chain/pipeline/run/: {sum(run.values())} lines {run}"
    large = {str(p.relative_to(PACKAGE)): lines(p) for p in PACKAGE.rglob("*.py") if lines(p) > 400}
    assert len(large) <= 4, large
