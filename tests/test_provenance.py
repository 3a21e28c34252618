"""chain.pipeline.provenance: what the article states about the run that produced it.

Every value is a function of the checkout and the configuration, never of the clock:
the date is the commit's, so a rebuild gives the same bytes."""

from __future__ import annotations

import os
import shutil
import subprocess

import pytest

from chain.pipeline.provenance import (
    NOT_GIT,
    config_hash,
    git_state,
    package_versions,
    run_provenance,
)

needs_git = pytest.mark.skipif(shutil.which("git") is None, reason="git is not installed")


def test_config_hash_follows_the_values_not_the_key_order():
    config = {"run_name": "paper", "launch": {"count": 12, "v0_min_m_s": 0.021}}
    reordered = {"launch": {"v0_min_m_s": 0.021, "count": 12}, "run_name": "paper"}
    changed = {"run_name": "paper", "launch": {"count": 13, "v0_min_m_s": 0.021}}
    assert config_hash(config) == config_hash(reordered)
    assert config_hash(config) != config_hash(changed)
    assert len(config_hash(config)) == 12


def test_outside_a_checkout_says_so(tmp_path):
    assert git_state(tmp_path) == {"commit": NOT_GIT, "date": None, "dirty": False}


def _git(folder, *args, date="2001-02-03T04:05:06+00:00"):
    env = {
        **os.environ,
        "GIT_AUTHOR_NAME": "a", "GIT_AUTHOR_EMAIL": "a@b", "GIT_COMMITTER_NAME": "a",
        "GIT_COMMITTER_EMAIL": "a@b", "GIT_AUTHOR_DATE": date, "GIT_COMMITTER_DATE": date,
    }  # fmt: skip
    subprocess.run(["git", "-C", str(folder), *args], check=True, env=env, capture_output=True)


@needs_git
def test_commit_date_and_uncommitted_changes(tmp_path):
    _git(tmp_path, "init", "-q")
    (tmp_path / "config.yaml").write_text("run_name: paper\n")
    _git(tmp_path, "add", "config.yaml")
    _git(tmp_path, "commit", "-q", "-m", "first")
    state = git_state(tmp_path)
    assert state["date"] == "2001-02-03"  # the commit's date, not today's
    assert len(state["commit"]) == 12 and not state["dirty"]
    # An untracked file (results/) is not a change; an edited tracked file is.
    (tmp_path / "results.txt").write_text("x")
    assert not git_state(tmp_path)["dirty"]
    (tmp_path / "config.yaml").write_text("run_name: other\n")
    assert git_state(tmp_path)["dirty"]
    assert git_state(tmp_path)["commit"] == state["commit"]


def test_versions_and_the_whole_record(tmp_path):
    versions = package_versions(["numpy", "no-such-distribution-hertzchain"])
    assert versions["numpy"].split(".")[0].isdigit()
    assert versions["no-such-distribution-hertzchain"] == "not installed"
    record = run_provenance({"run_name": "x"}, tmp_path)
    assert record == run_provenance({"run_name": "x"}, tmp_path)  # no clock in it
    assert set(record) == {"commit", "date", "dirty", "config_hash", "versions"}
