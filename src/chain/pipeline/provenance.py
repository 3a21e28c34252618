"""Which run produced an article: commit, commit date, config hash and package versions.

Everything here is a function of the inputs, never of the clock, so the same checkout and
configuration give the same article bytes: the date is the commit's (UTC), not today's.
Outside a git checkout (a copied workflow, an unpacked archive) or without git, the
commit and date say so; uncommitted changes are named as such, not hidden.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import subprocess
from collections.abc import Iterable, Mapping
from importlib import metadata

#: Packages whose versions the article states (distribution names).
PACKAGES = ("hertzchain", "numpy", "scipy", "pandas", "numba", "matplotlib", "snakemake", "typst")

NOT_GIT = "not a git checkout"


def config_hash(config: Mapping) -> str:
    """First 12 hex digits of the SHA-256 of ``config`` as canonical JSON (keys sorted):
    two runs with the same hash had the same configuration."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:12]


def _git(directory: str | os.PathLike, *args: str) -> str | None:
    """Output of ``git -C directory args``, or None where git or the checkout is absent."""
    try:
        done = subprocess.run(
            ["git", "-C", os.fspath(directory), *args],
            capture_output=True,
            text=True,
            timeout=20,
            check=False,
            env={**os.environ, "LC_ALL": "C", "TZ": "UTC"},
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def git_state(directory: str | os.PathLike) -> dict:
    """``{"commit", "date", "dirty"}`` of the checkout holding ``directory``: commit
    (12 hex digits), commit date (UTC, YYYY-MM-DD) and whether tracked files differ from
    it; commit :data:`NOT_GIT` and date None outside a git checkout."""
    inside = _git(directory, "rev-parse", "--is-inside-work-tree")
    commit = _git(directory, "rev-parse", "--short=12", "HEAD") if inside == "true" else None
    if not commit:
        return {"commit": NOT_GIT, "date": None, "dirty": False}
    date = _git(directory, "show", "-s", "--format=%cd", "--date=format-local:%Y-%m-%d", "HEAD")
    changes = _git(directory, "status", "--porcelain", "--untracked-files=no")
    return {"commit": commit, "date": date, "dirty": bool(changes)}


def package_versions(names: Iterable[str] = PACKAGES) -> dict[str, str]:
    """Installed version of each distribution in ``names`` ('not installed' if absent),
    and of Python."""
    versions = {"python": platform.python_version()}
    for name in names:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions


def run_provenance(config: Mapping, directory: str | os.PathLike) -> dict:
    """The provenance the article prints: ``commit``, ``date``, ``dirty``,
    ``config_hash`` and ``versions`` (see the functions above).

    Parameters
    ----------
    config : mapping
        The run's configuration as Snakemake holds it (after overlays).
    directory : path
        A directory of the workflow's checkout (the Snakefile's).
    """
    return {
        **git_state(directory),
        "config_hash": config_hash(config),
        "versions": package_versions(),
    }
