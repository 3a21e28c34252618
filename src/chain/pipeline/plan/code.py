"""Which source files a workflow script runs: the rule inputs that follow the code.

A rule must rerun when the code its script runs changes, and only then. The files are
read off the import statements (``ast``; nothing is imported), transitively, so that a
new import in the library needs no edit in the rules.
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
#: [[module, names], ...]]}, and the paths read in this process, not yet saved.
_KNOWN: dict[str, list] = {}
_UNSAVED: set[str] = set()


def remember_imports(store: str | os.PathLike) -> None:
    """Keep the import statements read between processes (parsing them took ~0.3 s of
    every Snakemake command) in the JSON file ``store``: call once before the rules ask
    for their code, and :func:`save_imports` after. A file is read again only when its
    modification time or size changed; a missing or unreadable store is an empty one."""
    try:
        known = json.loads(Path(store).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        known = {}
    if isinstance(known, dict):
        _KNOWN.update(known)


def save_imports(store: str | os.PathLike) -> None:
    """Write the import statements known now to ``store`` (a path; atomically, only when
    a file was read that it did not hold). One that cannot be written is left as it is."""
    if _UNSAVED:
        try:
            write_text_atomic(json.dumps(_KNOWN, sort_keys=True), store)
        except OSError:
            return
        _UNSAVED.clear()


def _imported_names(path: Path) -> list[tuple[str, list[str]]]:
    """(module, names) of each import statement of ``path``, anywhere in the file."""
    status = path.stat()
    return _parsed_imports(path, status.st_mtime_ns, status.st_size)


@cache
def _parsed_imports(path: Path, mtime_ns: int, size: int) -> list[tuple[str, list[str]]]:
    """:func:`_imported_names` of one version of a file, parsed once per version."""
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
    """The import statements of ``path``, parsed; relative ones made absolute."""
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
    """Every statement of ``body`` and of the blocks nested in it: unlike ``ast.walk``,
    not the expressions, most of a module's nodes."""
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
    """The file of module ``dotted`` under the package folder ``root``, or None."""
    relative = Path(*dotted.split(".")[1:])
    for candidate in (root / relative / "__init__.py", (root / relative).with_suffix(".py")):
        if candidate.is_file():
            return candidate
    return None


@cache
def _package_closure(root: Path, start: Path) -> frozenset[Path]:
    """Every package file that importing ``start`` (a package file) runs."""
    seen: set[Path] = set()
    todo = [start]
    while todo:
        path = todo.pop()
        if path not in seen:
            seen.add(path)
            for module, names in _imported_names(path):
                todo += _targets(root, module, names)
    return frozenset(seen)


def _targets(root: Path, module: str, names: list[str]) -> list[Path]:
    """Package files an import statement runs: the module's, the ``__init__`` files of
    the packages it is in, and ``y`` of ``from chain.x import y`` if a submodule."""
    if module != PACKAGE and not module.startswith(PACKAGE + "."):
        return []
    parts = module.split(".")
    files = [_module_file(root, ".".join(parts[:k])) for k in range(1, len(parts) + 1)]
    files += [_module_file(root, f"{module}.{name}") for name in names]
    return [f for f in files if f is not None]


def script_sources(script: str | os.PathLike, package_dir: str | os.PathLike) -> list[str]:
    """Source files ``script`` (``workflow/scripts/fig4_delay_vs_force.py``) runs besides
    itself: its local helpers and the files it and they import of ``package_dir``
    (``src/chain``), transitively; sorted, relative to the current directory (a moved or
    copied checkout names the same inputs)."""
    script, root = Path(script).resolve(), Path(package_dir).resolve()
    files = {f for m, _ in _imported_names(script) if (f := script.parent / f"{m}.py").is_file()}
    for source in [script, *files]:
        for module, names in _imported_names(source):
            for target in _targets(root, module, names):
                files |= _package_closure(root, target)
    here = Path.cwd().resolve()
    return sorted(os.path.relpath(path, here) for path in files)


def module_sources(module: str, package_dir: str | os.PathLike) -> list[Path]:
    """The files of the package folder ``package_dir`` (``src/chain``) that importing
    ``module`` (``chain.apparatus.dataset_check``) runs, absolute and sorted: its own, the
    ``__init__`` files of the packages it is in, and what they import, transitively."""
    root = Path(package_dir).resolve()
    return sorted(set().union(*(_package_closure(root, f) for f in _targets(root, module, []))))
