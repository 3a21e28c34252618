"""What the job server (chain.pipeline.job_server) loads before its jobs need it: the
modules the workflow's scripts import, the figures' warm-up, and numba's cached kernels
before each job that integrates.

A step here runs in the server between two jobs, so a job that arrives waits at most
for one import; what a job forked early lacks it imports itself, as in its own process.
"""

from __future__ import annotations

import ast
import importlib
import sys
from pathlib import Path

#: The package whose modules hold numba kernels (chain.physics).
KERNEL_PACKAGE = "chain.physics"

#: What Snakemake's preamble of a Python script imports, in each job's process before
#: the script's first line (snakemake.script.PythonScript.generate_preamble; ~0.13 s).
PREAMBLE_IMPORTS = ("snakemake.iocontainers", "snakemake.logging")


def preload_steps(scripts: Path, address: str) -> list:
    """The server's preload as steps to run between jobs: one import per module the
    ``scripts`` import at their top level (their local helpers too; one that fails is
    left for the job to report), Snakemake's preamble's (:data:`PREAMBLE_IMPORTS`)
    first, then the figures' warm-up (:func:`chain.report.figures.style.warm_up`) and
    the "ready" line. numba's kernels are not part of it: :func:`load_kernels_for`."""

    def importing(module: str):
        def step() -> None:
            sys.path.insert(0, str(scripts))
            try:
                importlib.import_module(module)
            except Exception as error:  # the job, importing it, fails the same way
                print(f"job server: not preloaded {module}: {error!r}", flush=True)
            finally:
                sys.path.remove(str(scripts))

        return step

    def figures() -> None:
        # A figure job's first save built matplotlib's mathtext parser, imported the
        # PDF backend and loaded the fonts (~0.4 s a job): once here instead.
        style = sys.modules.get("chain.report.figures.style")
        try:
            if style is not None:
                style.warm_up()
        except Exception as error:  # a figure job that fails so reports it itself
            print(f"job server: no warm-up of the figures: {error!r}", flush=True)

    def ready() -> None:
        print(f"job server: ready at {address}", flush=True)

    modules = sorted(_top_level_imports(scripts) - set(PREAMBLE_IMPORTS))
    return [*(importing(m) for m in (*PREAMBLE_IMPORTS, *modules)), figures, ready]


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
    modules = [m for m in _script_imports(Path(script)) if _defines_kernels(m)]
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


def _defines_kernels(module: str) -> bool:
    """Whether ``module`` is one of :data:`KERNEL_PACKAGE`'s."""
    return module.startswith(KERNEL_PACKAGE)


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
    modules: set[str] = set()
    for node in body:
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            modules.add(node.module)
    return modules
