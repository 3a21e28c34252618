"""The GitHub Actions workflow (.github/workflows/ci.yml): valid against the workflow
schema bundled with check-jsonschema (offline), so a broken file fails here before it
fails on GitHub; its commands are those of the page on CI (docs/ci.md), verbatim, and
the quick start's are the README's, so what CI runs is what a user types."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
WORKFLOWS = sorted((ROOT / ".github" / "workflows").glob("*.yml"))
#: Commands of the project a step may run; they must appear in docs/ci.md verbatim.
PROJECT_COMMANDS = ("pip ", "python ", "snakemake ", "hertzchain ")
#: The quick start's commands: CI runs them, and the README gives them.
QUICK_START = ('pip install -e ".[test]"', "snakemake --cores 2", "python -m pytest")


def validate(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "check_jsonschema", "--builtin-schema",
         "vendor.github-workflows", str(path)],
        capture_output=True, text=True, check=False, stdin=subprocess.DEVNULL,
    )  # fmt: skip


def test_workflows_validate_against_the_schema():
    assert WORKFLOWS, "no workflow under .github/workflows"
    for path in WORKFLOWS:
        result = validate(path)
        assert result.returncode == 0 and "ok" in result.stdout, result.stdout + result.stderr


def test_a_broken_workflow_fails_validation(tmp_path):
    """The check can fail: a job with `step:` instead of `steps:`."""
    broken = tmp_path / "broken.yml"
    broken.write_text("on: push\njobs:\n  a:\n    runs-on: ubuntu-latest\n    step: []\n")
    assert validate(broken).returncode != 0


def _steps(workflow: dict):
    for job in workflow["jobs"].values():
        yield from job["steps"]


def test_steps_are_the_documented_commands_and_keep_the_run():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    page = (ROOT / "docs" / "ci.md").read_text(encoding="utf-8")
    assert "docs/ci.md" in readme  # the README leads to the page
    workflow = yaml.safe_load(WORKFLOWS[0].read_text(encoding="utf-8"))
    commands = [s["run"].strip() for s in _steps(workflow) if "run" in s]
    project = [c for c in commands if c.startswith(PROJECT_COMMANDS)]
    assert set(QUICK_START) <= set(project)
    for command in QUICK_START:
        assert command in readme, f"the README's quick start lacks {command}"
    missing = [c for c in project if c not in page]
    assert not missing, f"commands of the workflow that docs/ci.md does not give: {missing}"
    uploads = [s for s in _steps(workflow) if s.get("uses", "").startswith("actions/upload")]
    assert {u["with"]["name"] for u in uploads} == {"paper-run", "paper-run-extras"}
    for upload in uploads:
        assert re.search(r"results/\w+/article.pdf", upload["with"]["path"])  # a run's article
        assert upload["with"]["name"] in page  # the page says how to get it


def _installs(job: dict) -> list[str]:
    return [s["run"].strip() for s in job["steps"] if s.get("run", "").startswith("pip install")]


def _python(job: dict) -> str:
    (version,) = [s["with"]["python-version"] for s in job["steps"]
                  if s.get("uses", "").startswith("actions/setup-python")]  # fmt: skip
    return version


def test_runs_install_their_pythons_lock_and_a_weekly_job_the_newest():
    """The runs install the lock of their Python with hashes, then the project
    without dependencies; one scheduled job installs the ranges' newest versions (no lock)
    and runs the paper run, the number check and the tests."""
    workflow = yaml.safe_load(WORKFLOWS[0].read_text(encoding="utf-8"))
    locked, unlocked = {}, {}
    for name, job in workflow["jobs"].items():
        installs = _installs(job)
        (locked if any("-r requirements/" in c for c in installs) else unlocked)[name] = job
    assert locked and len(unlocked) == 1
    for name, job in locked.items():
        lock = f"requirements/py{_python(job).replace('.', '')}.lock"
        assert (ROOT / lock).is_file(), f"{name}: no {lock} for Python {_python(job)}"
        assert _installs(job) == [f"pip install --require-hashes -r {lock}",
                                  "pip install --no-deps -e ."], name  # fmt: skip
    (newest,) = unlocked.values()
    assert "schedule" in newest["if"] and "push" not in newest["if"]
    assert _installs(newest)[0] == 'pip install -e ".[test]"'  # the quick start
    commands = [s["run"].strip() for s in newest["steps"] if "run" in s]
    assert {"snakemake --cores 2", "python -m pytest"} <= set(commands)
    assert any(c.startswith("hertzchain check") for c in commands)
    schedule = workflow[True]["schedule"] if True in workflow else workflow["on"]["schedule"]
    assert schedule  # YAML 1.1 reads the key `on` as True
