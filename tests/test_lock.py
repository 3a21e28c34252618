"""The locks (requirements/py3XX.lock): for each locked Python, an exact version with
its hashes of every dependency and extra of pyproject.toml, inside the range
pyproject.toml gives, made by the command its header and requirements/lock.sh give."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name

from chain.pipeline.provenance.record import read_lock

ROOT = Path(__file__).resolve().parents[1]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
SCRIPT = (ROOT / "requirements" / "lock.sh").read_text(encoding="utf-8")
LOCKS = sorted((ROOT / "requirements").glob("py3*.lock"))
#: Pythons the script locks, from its loop: `for version in 3.11 3.12 3.13; do`.
LOCKED_PYTHONS = re.search(r"for version in ([\d. ]+); do", SCRIPT).group(1).split()


def _python(lock: Path) -> str:
    """'3.12' for py312.lock."""
    digits = lock.stem.removeprefix("py")
    return f"{digits[0]}.{digits[1:]}"


def _requirements() -> list[tuple[str, Requirement]]:
    """(extra or '', requirement) of every dependency and every extra's."""
    found = [("", Requirement(text)) for text in PROJECT["dependencies"]]
    for extra, texts in PROJECT["optional-dependencies"].items():
        found += [(extra, Requirement(text)) for text in texts]
    return found


def test_a_lock_for_each_python_the_script_locks_and_the_project_supports():
    assert [_python(lock) for lock in LOCKS] == LOCKED_PYTHONS
    supported = SpecifierSet(PROJECT["requires-python"])
    assert LOCKED_PYTHONS and all(supported.contains(python) for python in LOCKED_PYTHONS)


@pytest.mark.parametrize("lock", LOCKS, ids=lambda path: path.name)
def test_the_lock_pins_every_dependency_inside_its_range(lock):
    pins = read_lock(lock)
    python = _python(lock)
    problems = []
    for extra, requirement in _requirements():
        environment = {"python_version": python, "extra": extra}
        if requirement.marker is not None and not requirement.marker.evaluate(environment):
            continue
        version = pins.get(canonicalize_name(requirement.name))
        if version is None:
            problems.append(f"{requirement} ({extra or 'dependency'}): not pinned")
        elif not requirement.specifier.contains(version, prereleases=True):
            problems.append(f"{requirement} ({extra or 'dependency'}): pinned at {version}")
    assert not problems, f"{lock.name}: " + "; ".join(problems)
    assert "hertzchain" not in pins  # the project itself is installed from the checkout


@pytest.mark.parametrize("lock", LOCKS, ids=lambda path: path.name)
def test_every_pin_has_a_hash_and_the_header_gives_the_command(lock):
    text = lock.read_text(encoding="utf-8")
    entries = re.split(r"\n(?=[A-Za-z0-9])", text.split("\n", 2)[2].strip())
    assert len(entries) == len(read_lock(lock)) > 30
    unhashed = [entry.split()[0] for entry in entries if "--hash=sha256:" not in entry]
    assert not unhashed, f"{lock.name}: pins without a hash: {unhashed}"
    # The header's command is the script's, for this Python and this file.
    command = text.splitlines()[1].removeprefix("#").strip()
    assert command.startswith("uv pip compile pyproject.toml --generate-hashes")
    assert f"--python-version {_python(lock)}" in command
    assert command.endswith(f"-o requirements/{lock.name}")
    for flag in ("--only-binary :all:", "--python-platform x86_64-manylinux_2_28",
                 "--extra test --extra slurm --extra lammps"):  # fmt: skip
        assert flag in command and flag in " ".join(SCRIPT.split())
