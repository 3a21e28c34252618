"""Which run produced an article: commit, commit date, config hash and package versions,
and whether those versions are the lock's.

Never the clock: the same checkout and config give the same article bytes (the date is
the commit's). Every installed version is recorded, and which differ from the Python's
lock (``requirements/py3XX.lock``): a number that moved can be traced to its release.
"""

from __future__ import annotations

import hashlib
import json
import os
import platform
import re
import subprocess
import sys
from collections.abc import Iterable, Mapping
from importlib import metadata
from pathlib import Path

#: Packages whose versions the article states (distribution names).
PACKAGES = ("hertzchain", "numpy", "scipy", "pandas", "numba", "matplotlib", "snakemake", "typst")

NOT_GIT = "not a git checkout"
NOT_INSTALLED = "not installed"

#: Folder of the locks in the checkout (py311.lock, ...), and a pin: ``name==version``.
LOCK_FOLDER = "requirements"
_PIN = re.compile(r"^([A-Za-z0-9][A-Za-z0-9._-]*)==([^\s;\\]+)", re.MULTILINE)


def config_hash(config: Mapping) -> str:
    """First 12 hex digits of the SHA-256 of ``config`` as canonical JSON (keys sorted):
    two runs with the same hash had the same configuration."""
    text = json.dumps(config, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:12]


def _git(directory: str | os.PathLike, *args: str) -> str | None:
    """Output of ``git -C directory args``, or None where git or the checkout is absent."""
    # No optional lock: `git status` would otherwise rewrite the checkout's index.
    command = ["git", "--no-optional-locks", "-C", os.fspath(directory), *args]
    env = {**os.environ, "LC_ALL": "C", "TZ": "UTC"}
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=20, env=env)
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() if done.returncode == 0 else None


def git_state(directory: str | os.PathLike) -> dict:
    """``{"commit", "date", "dirty"}`` of the checkout holding ``directory`` (a path):
    commit (12 hex digits), commit date (UTC, YYYY-MM-DD) and whether tracked files
    differ from it; commit :data:`NOT_GIT` and date None outside a git checkout."""
    inside = _git(directory, "rev-parse", "--is-inside-work-tree")
    commit = _git(directory, "rev-parse", "--short=12", "HEAD") if inside == "true" else None
    if not commit:
        return {"commit": NOT_GIT, "date": None, "dirty": False}
    date = _git(directory, "show", "-s", "--format=%cd", "--date=format-local:%Y-%m-%d", "HEAD")
    changes = _git(directory, "status", "--porcelain", "--untracked-files=no")
    return {"commit": commit, "date": date, "dirty": bool(changes)}


def package_versions(names: Iterable[str] = PACKAGES) -> dict[str, str]:
    """Installed version of each distribution in ``names`` (distribution names; 'not
    installed' if absent), and of Python."""
    versions = {"python": platform.python_version()}
    for name in names:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = NOT_INSTALLED
    return versions


def normalized_name(name: str) -> str:
    """A distribution's name as the package index compares it (PEP 503):
    ``Ruamel.YAML`` and ``ruamel_yaml`` are ``ruamel-yaml``."""
    return re.sub(r"[-_.]+", "-", name).lower()


def installed_distributions() -> dict[str, str]:
    """Version of every distribution installed where this Python imports from, by
    normalized name, sorted (the first found where one is installed twice, as ``import``
    finds it)."""
    found: dict[str, str] = {}
    for distribution in metadata.distributions():
        fields = distribution.metadata  # parses the file: once per distribution
        name = fields["Name"]
        if name:  # a broken install has no name; it is no package of ours
            found.setdefault(normalized_name(name), fields["Version"])
    return dict(sorted(found.items()))


def lock_path(directory: str | os.PathLike, python: tuple[int, int] | None = None) -> Path:
    """The lock of Python ``python`` ((major, minor); default the running one) in the
    checkout whose top folder is ``directory``: ``requirements/py311.lock`` for 3.11."""
    major, minor = python or sys.version_info[:2]
    return Path(directory) / LOCK_FOLDER / f"py{major}{minor}.lock"


def read_lock(path: str | os.PathLike) -> dict[str, str]:
    """The pins of the lock file ``path``: ``{normalized name: version}``."""
    text = Path(path).read_text(encoding="utf-8")
    return {normalized_name(name): version for name, version in _PIN.findall(text)}


def compare_with_lock(
    directory: str | os.PathLike, installed: Mapping[str, str] | None = None
) -> dict:
    """How the ``installed`` packages (``{normalized name: version}``; default
    :func:`installed_distributions`) compare with the running Python's lock in the
    checkout whose top folder is ``directory``: ``{"file", "matches", "differ", "note"}``,
    the lock (relative to the checkout), whether every locked package is installed at its
    locked version, and ``{name: {"locked", "installed"}}`` for each one that is not.
    Without a lock for this Python, ``file`` and ``matches`` are None and ``note`` says so.
    """
    path = lock_path(directory)
    relative = f"{LOCK_FOLDER}/{path.name}"
    if not path.is_file():
        note = (
            f"no {relative} for Python {platform.python_version()} in this copy of the "
            "workflow (not a checkout, or an unlocked Python): versions not compared"
        )
        return {"file": None, "matches": None, "differ": {}, "note": note}
    installed = installed_distributions() if installed is None else installed
    differ = {
        name: {"locked": locked, "installed": installed.get(name, NOT_INSTALLED)}
        for name, locked in sorted(read_lock(path).items())
        if installed.get(name) != locked
    }
    note = f"{len(differ)} package(s) differ from the lock" if differ else "as locked"
    return {"file": relative, "matches": not differ, "differ": differ, "note": note}


def lock_warnings(provenance: Mapping | None) -> list[str]:
    """What a check says about the versions recorded in ``provenance`` (a run's
    summary.json block, :func:`run_provenance`, or None) against the lock: a line naming
    every package that differs, a line when nothing could be compared, or nothing."""
    lock = (provenance or {}).get("lock")
    if not lock:
        return ["summary.json records no comparison with the lock (an older run?)"]
    if lock["matches"] is None:
        return [lock["note"]]
    if lock["matches"]:
        return []
    differences = ", ".join(
        f"{name} {versions['installed']} (locked {versions['locked']})"
        for name, versions in lock["differ"].items()
    )
    return [
        f"the run's packages differ from {lock['file']}: {differences}; the locked "
        f"environment: pip install --require-hashes -r {lock['file']} && "
        "pip install --no-deps -e ."
    ]


def run_provenance(config: Mapping, directory: str | os.PathLike) -> dict:
    """The provenance of a run of ``config`` (as Snakemake holds it, after overlays) from
    the checkout holding ``directory``, for summary.json and the article: ``commit``,
    ``date``, ``dirty``, ``config_hash``, ``versions`` (Python and the main packages),
    ``installed`` (every distribution) and ``lock`` (:func:`compare_with_lock`)."""
    installed = installed_distributions()
    return {
        **git_state(directory),
        "config_hash": config_hash(config),
        "versions": package_versions(),
        "installed": installed,
        "lock": compare_with_lock(directory, installed),
    }
