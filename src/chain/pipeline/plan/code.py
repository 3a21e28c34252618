"""Which source files a workflow script runs: the rule inputs that follow the code.

A rule must rerun when the code its script runs changes, and only then. The files are
read off the import statements (``ast``, nothing is imported): the script's own local
helpers (``_logging.py`` beside it), and every module of the ``chain`` package it
imports, followed transitively, with the ``__init__`` files on the way. A new import
in the library therefore needs no edit in the rules.
"""

from __future__ import annotations

import ast
import json
import os
from collections.abc import Iterator
from functools import cache
from pathlib import Path

from chain.atomic import write_text_atomic

#: The package whose files are followed.
PACKAGE = "chain"

#: Import statements read in this process or an earlier one: {path: [mtime_ns, size,
#: [[module, names], ...]]} (see :func:`remember_imports`).
_KNOWN: dict[str, list] = {}
#: Files of :data:`_KNOWN` read in this process, not yet in the store.
_UNSAVED: set[str] = set()


def remember_imports(store: str | os.PathLike) -> None:
    """Keep the import statements read between processes, in the JSON file ``store``:
    call once before the rules ask for their code, and :func:`save_imports` after.

    Every Snakemake command (and every job on a cluster) parses the workflow, and
    parsing the ~100 package files for their imports took ~0.3 s of it; a file is read
    again only when its modification time (ns) or size changed, as Python's own
    bytecode cache decides. A missing or unreadable store is an empty one.
    """
    try:
        known = json.loads(Path(store).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        known = {}
    if isinstance(known, dict):
        _KNOWN.update(known)


def save_imports(store: str | os.PathLike) -> None:
    """Write the import statements known now to ``store`` (atomically; only when a
    file was read that the store did not hold). A store that cannot be written (a
    read-only checkout) is left as it is: it only saves time."""
    if _UNSAVED:
        try:
            write_text_atomic(json.dumps(_KNOWN, sort_keys=True), store)
        except OSError:
            return
        _UNSAVED.clear()


def _imported_names(path: Path) -> list[tuple[str, list[str]]]:
    """(module, names) of each import statement of ``path``, anywhere in the file;
    relative imports are made absolute for files inside the package."""
    status = path.stat()
    return _parsed_imports(path, status.st_mtime_ns, status.st_size)


@cache
def _parsed_imports(path: Path, mtime_ns: int, size: int) -> list[tuple[str, list[str]]]:
    """:func:`_imported_names` of one version of a file. Every rule asks for the same
    few dozen modules: parsed once per version (the key), not once per rule, and not
    again in the next process (:func:`remember_imports`)."""
    try:
        stored_mtime, stored_size, imports = _KNOWN[str(path)]
        if [stored_mtime, stored_size] == [mtime_ns, size]:
            return [(str(module), [str(name) for name in names]) for module, names in imports]
    except (KeyError, TypeError, ValueError):  # not known, or a damaged entry
        pass
    found = _read_imports(path)
    _KNOWN[str(path)] = [mtime_ns, size, found]
    _UNSAVED.add(str(path))
    return found


def _read_imports(path: Path) -> list[tuple[str, list[str]]]:
    """The import statements of ``path``, parsed."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in _statements(tree.body):
        if isinstance(node, ast.Import):
            found += [(alias.name, []) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                parts = _module_name(path).split(".")
                base = parts[: len(parts) - node.level]
                module = ".".join([*base, module] if module else base)
            found.append((module, [alias.name for alias in node.names]))
    return found


def _statements(body: list) -> Iterator[ast.AST]:
    """Every statement of ``body`` and of the blocks nested in it (functions, classes,
    if/try/with/for/match bodies). An import is a statement: unlike ``ast.walk``, this
    does not visit the expressions, most of a module's nodes."""
    for node in body:
        yield node
        for block in ("body", "orelse", "finalbody", "handlers", "cases"):
            yield from _statements(getattr(node, block, ()))


def _module_name(path: Path) -> str:
    """Dotted name of a file of the package (``chain.physics.model``)."""
    parts = list(path.with_suffix("").parts)
    parts = parts[len(parts) - 1 - parts[::-1].index(PACKAGE) :]
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def _module_file(root: Path, dotted: str) -> Path | None:
    """The file of module ``dotted`` under the package folder ``root``, or None (asked
    thousands of times at parse time, for a few hundred names)."""
    relative = Path(*dotted.split(".")[1:])
    for candidate in (root / relative / "__init__.py", (root / relative).with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


def _with_parents(root: Path, dotted: str) -> list[Path]:
    """The module's file and the ``__init__`` files of the packages it is in."""
    parts = dotted.split(".")
    files = [_module_file(root, ".".join(parts[:k])) for k in range(1, len(parts) + 1)]
    return [f for f in files if f is not None]


@cache
def _package_closure(root: Path, start: Path) -> frozenset[Path]:
    """Every package file that importing ``start`` (a package file) runs."""
    seen: set[Path] = set()
    todo = [start]
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        for module, names in _imported_names(path):
            todo += _targets(root, module, names)
    return frozenset(seen)


def _targets(root: Path, module: str, names: list[str]) -> list[Path]:
    """Package files an import statement runs (``from chain.x import y``: y may be a
    submodule)."""
    if module != PACKAGE and not module.startswith(PACKAGE + "."):
        return []
    files = _with_parents(root, module)
    files += [f for name in names if (f := _module_file(root, f"{module}.{name}"))]
    return files


def script_sources(script: str | os.PathLike, package_dir: str | os.PathLike) -> list[str]:
    """Source files a workflow script runs, besides itself: its local helpers and the
    package files it imports, transitively.

    Parameters
    ----------
    script : path
        The script (``workflow/scripts/fig4_delay_vs_force.py``).
    package_dir : path
        The ``chain`` package folder the jobs import (``src/chain``).

    Returns
    -------
    list of str
        Sorted paths relative to the current directory (so that a moved or copied
        checkout names the same inputs).
    """
    script, root = Path(script).resolve(), Path(package_dir).resolve()
    files = {script.parent / f"{m}.py" for m, _ in _imported_names(script)}
    files = {f for f in files if f.is_file()} | _package_files_run_by(script, root)
    here = Path.cwd().resolve()
    return sorted(os.path.relpath(path, here) for path in files)


def module_sources(module: str, package_dir: str | os.PathLike) -> list[Path]:
    """The package files that importing a module of the package runs: its own file,
    the ``__init__`` files of the packages it is in, and what they import, transitively.

    Parameters
    ----------
    module : str
        Dotted name (``chain.apparatus.dataset_check``).
    package_dir : path
        The ``chain`` package folder (``src/chain``).

    Returns
    -------
    list of Path
        Absolute paths, sorted.
    """
    root = Path(package_dir).resolve()
    return sorted(set().union(*(_package_closure(root, f) for f in _targets(root, module, []))))


def script_modules(script: str | os.PathLike, package_dir: str | os.PathLike) -> dict:
    """The package modules a workflow script runs (as :func:`script_sources` follows
    them), each with the top-level packages it imports anywhere in its file.

    Parameters
    ----------
    script : path
        The script (or Snakemake's copy of it, with its preamble).
    package_dir : path
        The ``chain`` package folder the jobs import (``src/chain``).

    Returns
    -------
    dict of str to set of str
        Dotted module name (``chain.physics.kernels``) -> imported top-level packages
        (``{"numba", "numpy", "chain"}``).
    """
    files = _package_files_run_by(Path(script).resolve(), Path(package_dir).resolve())
    return {
        _module_name(path): {module.split(".")[0] for module, _ in _imported_names(path) if module}
        for path in files
    }


def _package_files_run_by(script: Path, root: Path) -> set[Path]:
    """Every file of the package under ``root`` that ``script`` runs, transitively."""
    files: set[Path] = set()
    for module, names in _imported_names(script):
        for target in _targets(root, module, names):
            files |= _package_closure(root, target)
    return files
