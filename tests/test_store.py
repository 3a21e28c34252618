"""The result store (chain.pipeline.run.store): what a job stored comes back byte for
byte or not at all, the store is the user's alone, and entries appear whole. Its use in
a run: tests/test_reuse.py and tests/test_workflow.py."""

from __future__ import annotations

import os
import stat
import subprocess
from pathlib import Path

import pytest

from chain.pipeline.run.checksums import CHECKSUMS, write_checksums
from chain.pipeline.run.store import (
    STORE_VARIABLE,
    BadEntry,
    Store,
    StoreError,
    file_digest,
)


@pytest.fixture
def store(tmp_path) -> Store:
    return Store.open({STORE_VARIABLE: str(tmp_path / "store")})


@pytest.fixture
def outputs(tmp_path) -> list[str]:
    """A job's two outputs: a table, and a folder of two files (a dataset)."""
    run = tmp_path / "results" / "first"
    (run / "raw").mkdir(parents=True)
    (run / "table.csv").write_text("x,y\n1,2\n")
    (run / "raw" / "shot_0.csv").write_text("t,v\n0,1\n")
    (run / "raw" / "sub").mkdir()
    (run / "raw" / "sub" / "metadata.yaml").write_text("N: 25\n")
    return [str(run / "table.csv"), str(run / "raw")]


def elsewhere(outputs: list[str], tmp_path: Path) -> list[str]:
    """The same outputs in another run folder (not yet there)."""
    return [str(tmp_path / "results" / "second" / Path(p).name) for p in outputs]


def test_what_is_stored_comes_back_byte_for_byte_as_plain_files(store, outputs, tmp_path):
    assert store.put("ab" * 32, outputs, {"run": "first"})
    again = elsewhere(outputs, tmp_path)
    manifest = store.fetch("ab" * 32, again)
    assert manifest["run"] == "first"
    for first, second in zip(outputs, again):
        assert file_digest(first) == file_digest(second)
        for path in [Path(second), *Path(second).rglob("*")]:
            assert not path.is_symlink()
            assert os.stat(path).st_mode & 0o222  # a copy of the user's, not read-only
    assert store.fetch("cd" * 32, again) is None  # nothing stored under that key


def test_the_store_is_private_and_its_files_read_only(store, outputs):
    store.put("ab" * 32, outputs, {})
    assert stat.S_IMODE(store.root.stat().st_mode) == 0o700
    for path in store.entry("ab" * 32).rglob("*"):
        mode = stat.S_IMODE(path.stat().st_mode)
        assert not mode & 0o022, path  # nobody else may write
        if path.is_file():
            assert not mode & 0o200, path  # read-only, even for the user


@pytest.mark.parametrize("damage", ["altered", "truncated", "removed", "linked", "manifest"])
def test_a_damaged_entry_is_named_discarded_and_never_handed_on(store, outputs, tmp_path, damage):
    """A stored file altered, truncated, removed or replaced by a link, or a manifest
    cut short: fetch names the file, writes no output and discards the entry."""
    store.put("ab" * 32, outputs, {})
    files = store.entry("ab" * 32) / "files"
    shot = files / "1" / "shot_0.csv"
    os.chmod(shot, 0o600)
    if damage == "altered":
        shot.write_text("t,v\n0,2\n")  # same size, other bytes
    elif damage == "truncated":
        shot.write_text("t,v\n")
    elif damage == "removed":
        shot.unlink()
    elif damage == "linked":
        shot.unlink()
        shot.symlink_to(Path(outputs[1]) / "shot_0.csv")
    else:
        manifest = store.entry("ab" * 32) / "manifest.json"
        os.chmod(manifest, 0o600)
        manifest.write_text(manifest.read_text()[:40])
    again = elsewhere(outputs, tmp_path)
    with pytest.raises(BadEntry) as found:
        store.fetch("ab" * 32, again)
    named = "manifest.json" if damage == "manifest" else "shot_0.csv"
    assert named in str(found.value)
    assert not any(Path(p).exists() for p in again)
    assert not (tmp_path / "results" / "second").exists() or not list(
        (tmp_path / "results" / "second").iterdir()
    )
    assert not store.entry("ab" * 32).exists()
    assert store.fetch("ab" * 32, again) is None


def test_two_runs_storing_one_key_keep_one_whole_entry(store, outputs, tmp_path):
    """The second writer finds the entry there (renamed into place whole) and keeps it;
    a replacing writer (a forced run) swaps it; no staging folder is left."""
    assert store.put("ab" * 32, outputs, {"run": "first"})["run"] == "first"
    assert store.put("ab" * 32, outputs, {"run": "second"})["run"] == "first"
    assert store.fetch("ab" * 32, elsewhere(outputs, tmp_path))["run"] == "first"
    assert store.put("ab" * 32, outputs, {"run": "forced"}, replace=True)
    again = [str(tmp_path / "third" / Path(p).name) for p in outputs]
    assert store.fetch("ab" * 32, again)["run"] == "forced"
    assert list((store.root / "tmp").iterdir()) == []


def test_a_store_others_may_write_is_refused(tmp_path):
    """Another user's folder, or one writable by others (everyone, or a group it was not
    shared with on purpose), is refused with a message that names it."""
    folder = tmp_path / "open"
    folder.mkdir(mode=0o777)
    os.chmod(folder, 0o777)
    with pytest.raises(StoreError, match=f"{folder}.*writable by others"):
        Store.open({STORE_VARIABLE: str(folder)})
    os.chmod(folder, 0o770)
    with pytest.raises(StoreError, match="HERTZCHAIN_STORE_GROUP"):
        Store.open({STORE_VARIABLE: str(folder)})
    if os.getuid() == 0:  # as root, a folder of uid 65534 can be made
        os.chmod(folder, 0o700)
        os.chown(folder, 65534, -1)
        with pytest.raises(StoreError, match="belongs to uid 65534"):
            Store.open({STORE_VARIABLE: str(folder)})


def test_a_store_shared_on_purpose_is_open_to_its_group_alone(tmp_path, outputs):
    group = "nogroup" if _group_exists("nogroup") else None
    if group is None or os.getuid() != 0:
        pytest.skip("needs root and the group nogroup to share a store: not checked here")
    store = Store.open({STORE_VARIABLE: str(tmp_path / "shared"), "HERTZCHAIN_STORE_GROUP": group})
    store.put("ab" * 32, outputs, {})
    for path in [store.root, *store.root.rglob("*")]:
        info = path.stat()
        assert not stat.S_IMODE(info.st_mode) & 0o007, path  # never everyone
    assert stat.S_IMODE(store.root.stat().st_mode) == 0o2770
    stored = store.entry("ab" * 32) / "files" / "0"
    assert stat.S_IMODE(stored.stat().st_mode) == 0o440


def _group_exists(name: str) -> bool:
    import grp

    try:
        grp.getgrnam(name)
    except KeyError:
        return False
    return True


def test_checksums_list_every_file_as_sha256sum_reads_them(outputs, tmp_path):
    run = tmp_path / "results" / "first"
    write_checksums(run)
    lines = (run / CHECKSUMS).read_text().splitlines()
    assert [line.split("  ")[1] for line in lines] == [
        "raw/shot_0.csv",
        "raw/sub/metadata.yaml",
        "table.csv",
    ]
    check = subprocess.run(["sha256sum", "-c", CHECKSUMS], cwd=run, capture_output=True)
    assert check.returncode == 0, check.stdout


def _store_many(root: str, outputs: list[str], run: str) -> None:
    store = Store.open({STORE_VARIABLE: root})
    for k in range(20):
        store.put(f"{k:02d}" * 32, outputs, {"run": run})


def test_two_runs_storing_at_once_leave_only_whole_entries(tmp_path, outputs):
    """Two processes storing the same twenty results at the same time: every entry is
    whole (its files match its manifest) and the staging area is empty."""
    import multiprocessing

    root = str(tmp_path / "store")
    context = multiprocessing.get_context("fork")
    writers = [context.Process(target=_store_many, args=(root, outputs, run)) for run in ("a", "b")]
    for writer in writers:
        writer.start()
    for writer in writers:
        writer.join(timeout=300)
        assert writer.exitcode == 0
    store = Store.open({STORE_VARIABLE: root})
    for k in range(20):
        again = [str(tmp_path / f"check{k}" / Path(p).name) for p in outputs]
        assert store.fetch(f"{k:02d}" * 32, again)["run"] in ("a", "b")
    assert list((store.root / "tmp").iterdir()) == []
