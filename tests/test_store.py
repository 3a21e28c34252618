"""The result store (chain.pipeline.run.store): what a job stored comes back byte for
byte or not at all; the store's whole path is checked and the store held by
descriptor; a group store is its group's and no one else's; writes are flushed and a
killed fetch leaves nothing for long; ``hertzchain store`` says what it holds and
prunes it. The store's user: tests/test_reuse.py and tests/test_workflow.py."""

from __future__ import annotations

import datetime
import grp
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest

from chain import atomic
from chain.cli import main
from chain.pipeline.run import store_path
from chain.pipeline.run.checksums import CHECKSUMS, write_checksums
from chain.pipeline.run.staging import PREFIX, remove_stale_staging
from chain.pipeline.run.store import (
    GROUP_VARIABLE,
    STORE_VARIABLE,
    BadEntry,
    Store,
    StoreError,
    file_digest,
    stored_digest,
)

KEY, OTHER = "ab" * 32, "cd" * 32
#: Where /proc says which file a descriptor is (Linux).
PROC_FD = Path("/proc/self/fd")


@pytest.fixture
def store(tmp_path) -> Store:
    return Store.open({STORE_VARIABLE: str(tmp_path / "store")})


@pytest.fixture
def outputs(tmp_path) -> list[str]:
    """A job's two outputs: a table, and a folder of files (a dataset)."""
    run = tmp_path / "results" / "first"
    (run / "raw" / "sub").mkdir(parents=True)
    (run / "table.csv").write_text("x,y\n1,2\n")
    (run / "raw" / "shot_0.csv").write_text("t,v\n0,1\n")
    (run / "raw" / "sub" / "metadata.yaml").write_text("N: 25\n")
    return [str(run / "table.csv"), str(run / "raw")]


def elsewhere(outputs: list[str], tmp_path: Path, run: str = "second") -> list[str]:
    """The same outputs in another run folder (not yet there)."""
    return [str(tmp_path / "results" / run / Path(p).name) for p in outputs]


def staging_left(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.rglob(f"{PREFIX}*")) if folder.is_dir() else []


# ---- what is stored comes back, or nothing --------------------------------------------


def test_what_is_stored_comes_back_byte_for_byte_as_plain_files(store, outputs, tmp_path):
    """put returns the manifest it stored, whose digests are the outputs' (the caller
    need not hash again); fetch copies plain, writable files and returns it too."""
    manifest = store.put(KEY, outputs, {"run": "first"})
    assert [stored_digest(files) for files in manifest["outputs"]] == [
        file_digest(p) for p in outputs
    ]
    again = elsewhere(outputs, tmp_path)
    assert store.fetch(KEY, again) == manifest
    for first, second in zip(outputs, again):
        assert file_digest(first) == file_digest(second)
        for path in [Path(second), *Path(second).rglob("*")]:
            assert not path.is_symlink()
            assert os.stat(path).st_mode & 0o222  # a copy of the user's, not read-only
    assert store.fetch(OTHER, again) is None  # nothing stored under that key


def test_the_store_is_private_and_its_files_read_only(store, outputs):
    store.put(KEY, outputs, {})
    assert stat.S_IMODE(store.root.stat().st_mode) == 0o700
    for path in store.entry(KEY).rglob("*"):
        mode = stat.S_IMODE(path.stat().st_mode)
        assert not mode & 0o022, path  # nobody else may write
        if path.is_file():
            assert not mode & 0o200, path  # read-only, even for the user


def damage(store: Store, outputs: list[str], kind: str) -> str:
    """Damage the entry KEY one way; the name the error must give."""
    shot = store.entry(KEY) / "files" / "1" / "shot_0.csv"
    os.chmod(shot, 0o600)
    if kind == "altered":
        shot.write_text("t,v\n0,2\n")  # same size, other bytes
    elif kind == "truncated":
        shot.write_text("t,v\n")
    elif kind == "removed":
        shot.unlink()
    elif kind == "linked":
        shot.unlink()
        shot.symlink_to(Path(outputs[1]) / "shot_0.csv")
    else:
        manifest = store.entry(KEY) / "manifest.json"
        os.chmod(manifest, 0o600)
        manifest.write_text(manifest.read_text()[:40])
        return "manifest.json"
    return "shot_0.csv"


KINDS = ["altered", "truncated", "removed", "linked", "manifest"]


@pytest.mark.parametrize("kind", KINDS)
def test_a_damaged_entry_is_named_discarded_and_never_handed_on(store, outputs, tmp_path, kind):
    """A stored file altered, truncated, removed or replaced by a link, or a manifest
    cut short: fetch names the file, writes no output (no staging left either) and
    discards the entry."""
    store.put(KEY, outputs, {})
    named = damage(store, outputs, kind)
    again = elsewhere(outputs, tmp_path)
    with pytest.raises(BadEntry, match=named):
        store.fetch(KEY, again)
    run = tmp_path / "results" / "second"
    assert not run.exists() or not list(run.iterdir())
    assert not store.entry(KEY).exists()
    assert store.fetch(KEY, again) is None


@pytest.mark.parametrize("kind", KINDS)
def test_verify_checks_every_file_and_writes_nothing(store, outputs, tmp_path, kind):
    """verify (a dry run) returns the manifest of a whole entry, None for a missing
    one, and names a damaged one's file without discarding it; it copies nothing."""
    stored = store.put(KEY, outputs, {"paths": ["table.csv", "raw"]})
    assert store.verify(KEY, 2) == stored
    assert store.verify(OTHER, 2) is None
    named = damage(store, outputs, kind)
    before = sorted((p, p.lstat().st_mtime_ns) for p in tmp_path.rglob("*"))
    with pytest.raises(BadEntry, match=named):
        store.verify(KEY, 2)
    assert sorted((p, p.lstat().st_mtime_ns) for p in tmp_path.rglob("*")) == before


def test_two_runs_storing_one_key_keep_one_whole_entry(store, outputs, tmp_path):
    """The second writer finds the entry there and keeps it, and gets its manifest; a
    replacing writer (a forced run) swaps it; no staging folder is left."""
    first = store.put(KEY, outputs, {"run": "first"})
    assert store.put(KEY, outputs, {"run": "second"}) == first
    assert store.fetch(KEY, elsewhere(outputs, tmp_path))["run"] == "first"
    assert store.put(KEY, outputs, {"run": "forced"}, replace=True)["run"] == "forced"
    assert store.fetch(KEY, elsewhere(outputs, tmp_path, "third"))["run"] == "forced"
    assert list((store.root / "tmp").iterdir()) == []


@pytest.mark.parametrize("replace", [True, False])
def test_a_put_over_a_damaged_manifest_replaces_the_entry(store, outputs, tmp_path, replace):
    store.put(KEY, outputs, {"run": "first"})
    damage(store, outputs, "manifest")
    assert store.put(KEY, outputs, {"run": "again"}, replace=replace)["run"] == "again"
    assert store.fetch(KEY, elsewhere(outputs, tmp_path))["run"] == "again"
    assert list((store.root / "tmp").iterdir()) == []


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


# ---- the store's whole path, and the store held by descriptor -------------------------


def test_a_store_others_may_write_is_refused(tmp_path):
    """Another user's folder, or one writable by others (everyone, or a group it was not
    shared with on purpose), is refused with a message that names it."""
    folder = tmp_path / "open"
    folder.mkdir()
    os.chmod(folder, 0o777)
    with pytest.raises(StoreError, match=f"{folder}.*writable by others"):
        Store.open({STORE_VARIABLE: str(folder)})
    os.chmod(folder, 0o770)
    with pytest.raises(StoreError, match=GROUP_VARIABLE):
        Store.open({STORE_VARIABLE: str(folder)})
    mine = grp.getgrgid(os.getgid()).gr_name  # the user's group: a group store of it
    os.chmod(folder, 0o777)  # writable by everyone: refused, not made the group's
    with pytest.raises(StoreError, match="writable by others"):
        Store.open({STORE_VARIABLE: str(folder), GROUP_VARIABLE: mine})
    assert stat.S_IMODE(folder.stat().st_mode) == 0o777
    if os.getuid() == 0:  # as root, a folder of uid 65534 can be made
        os.chmod(folder, 0o700)
        os.chown(folder, 65534, -1)
        with pytest.raises(StoreError, match="belongs to uid 65534"):
            Store.open({STORE_VARIABLE: str(folder)})


@pytest.mark.parametrize("mode", [0o777, 0o775])
def test_a_folder_above_the_store_others_may_write_is_refused(tmp_path, mode):
    """A parent writable by everyone, or by a group (results/ under umask 002): the
    store is refused before anything is made in it, naming the folder and the fix; a
    sticky folder (like /tmp) is fine."""
    results = tmp_path / "results"
    results.mkdir()
    os.chmod(results, mode)
    with pytest.raises(StoreError, match=rf"{results} is writable by others .*chmod g-w,o-w"):
        Store.open({}, working_directory=tmp_path)
    assert list(results.iterdir()) == []
    os.chmod(results, 0o1777)
    assert Store.open({}, working_directory=tmp_path).root == tmp_path / "results" / ".store"


@pytest.mark.skipif(os.getuid() != 0, reason="needs root to make a folder of another user")
def test_a_folder_above_the_store_of_another_user_is_refused(tmp_path):
    os.chown(tmp_path, 65534, -1)
    with pytest.raises(StoreError, match=f"{tmp_path} belongs to uid 65534, .*swap the store"):
        Store.open({STORE_VARIABLE: str(tmp_path / "store")})


def test_opening_without_create_writes_nothing(tmp_path, outputs):
    """create=False (a dry run): None when there is no store, and no folder made; an
    existing store is opened and what it holds is left as it is."""
    environ = {STORE_VARIABLE: str(tmp_path / "deep" / "store")}
    assert Store.open(environ, create=False) is None
    assert not (tmp_path / "deep").exists()
    Store.open(environ).put(KEY, outputs, {})
    (tmp_path / "deep" / "store" / "tmp" / f"{PREFIX}0-999999999-{os.uname().nodename}").mkdir()
    before = sorted(p.name for p in (tmp_path / "deep").rglob("*"))
    assert Store.open(environ, create=False).verify(KEY, 2)["key"] == KEY
    assert sorted(p.name for p in (tmp_path / "deep").rglob("*")) == before


def test_a_store_swapped_after_it_is_opened_hands_nothing_of_the_swap_on(tmp_path, outputs):
    """The store's folder swapped for another tree whose entries match their manifests
    (a store of someone else's, with other bytes under the same key): the open store
    reads and writes the folder it opened, never the swapped tree."""
    root = tmp_path / "store"
    store = Store.open({STORE_VARIABLE: str(root)})
    store.put(KEY, outputs, {"run": "mine"})
    forged = Path(outputs[0])
    forged.write_text("x,y\n6,6\n")
    other = Store.open({STORE_VARIABLE: str(tmp_path / "forged")})
    other.put(KEY, outputs, {"run": "forged"})
    other.put(OTHER, outputs, {"run": "forged"})
    root.rename(tmp_path / "mine")
    (tmp_path / "forged").rename(root)
    again = elsewhere(outputs, tmp_path)
    assert store.fetch(KEY, again)["run"] == "mine"
    assert Path(again[0]).read_text() == "x,y\n1,2\n"
    assert store.fetch(OTHER, again) is None
    assert store.verify(OTHER, 2) is None
    store.put("ef" * 32, outputs, {"run": "mine"})
    assert (tmp_path / "mine" / "ef").is_dir() and not (root / "ef").exists()


def test_a_store_path_through_a_link_is_the_linked_folder(tmp_path, outputs):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    Store.open({STORE_VARIABLE: str(tmp_path / "link" / "store")}).put(KEY, outputs, {})
    assert (tmp_path / "real" / "store" / KEY[:2] / KEY / "manifest.json").is_file()


def test_a_refusal_names_a_file_system_whose_owners_cannot_be_trusted(tmp_path, monkeypatch):
    """On NFS (root squash), SMB or FAT, owners and modes need not be the accounts'
    own: a refusal says so, naming the file system."""
    table = tmp_path / "mountinfo"
    table.write_text(
        "22 1 8:1 / / rw - ext4 /dev/sda1 rw\n"
        f"40 22 0:50 / {tmp_path} rw,relatime shared:1 - nfs4 server:/home rw\n"
        f"41 40 0:51 / {tmp_path}/local\\040disk rw - ext4 /dev/sdb1 rw\n"
    )
    assert store_path.file_system(tmp_path / "a", table) == ("nfs4", str(tmp_path))
    assert store_path.file_system(tmp_path / "local disk" / "a", table)[0] == "ext4"
    assert store_path.file_system("/etc", table) == ("ext4", "/")
    real = store_path.file_system
    monkeypatch.setattr(store_path, "file_system", lambda path: real(path, table))
    os.chmod(tmp_path, 0o777)
    with pytest.raises(StoreError, match=r"is on a nfs4 file system .* cannot be made there"):
        Store.open({STORE_VARIABLE: str(tmp_path / "store")})


# ---- a store shared with a group --------------------------------------------------------


#: The chain package's source folder, for a Python of another account.
SOURCE = Path(__file__).resolve().parents[1] / "src"
#: Pythons another account may be able to run (this one may sit in root's home).
PYTHONS = [sys.executable, shutil.which("python3"), "/usr/bin/python3"]
AS_ANOTHER = textwrap.dedent("""
    import json, sys
    from chain.pipeline.run.store import Store, StoreError
    if len(sys.argv) == 1:
        sys.exit(0)  # a Python this account can run, and the store imports
    root, group, action, key, out = sys.argv[1:]
    try:
        store = Store.open({"HERTZCHAIN_STORE": root, "HERTZCHAIN_STORE_GROUP": group})
    except StoreError as error:
        sys.exit(f"refused: {error}")
    if action == "put":
        print(json.dumps(store.put(key, [out], {"run": "nobody's"})))
    else:
        print(json.dumps(store.fetch(key, [out])))
""")


def as_account(uid: int, groups: list[int], *args: str, python=sys.executable):
    """Run AS_ANOTHER with ``args`` as the account ``uid`` (its group: ``uid`` too) in
    the groups ``groups``."""
    try:
        return subprocess.run(
            [python, "-B", "-c", AS_ANOTHER, *args],
            user=uid, group=uid, extra_groups=groups, umask=0o022, cwd="/",
            env={"PYTHONPATH": str(SOURCE), "PATH": os.defpath},
            capture_output=True, text=True, stdin=subprocess.DEVNULL,
        )  # fmt: skip
    except OSError as error:  # a Python this account may not run
        return subprocess.CompletedProcess([python], 126, "", str(error))


@pytest.fixture
def lab_group():
    """A group made for the test, with ``nobody`` (uid 65534) in it, and a Python that
    nobody can run the store with; the group is removed after."""
    if os.getuid() != 0 or not (shutil.which("groupadd") and shutil.which("gpasswd")):
        pytest.skip("needs root, groupadd and gpasswd to make a group of two accounts")
    runs = [p for p in PYTHONS if p and as_account(65534, [], python=p).returncode == 0]
    if not runs:
        pytest.skip(f"uid 65534 can run no Python that imports {SOURCE}/chain: {PYTHONS}")
    name = f"hzlab{os.getpid()}{os.urandom(2).hex()}"
    subprocess.run(["groupadd", name], check=True, capture_output=True)
    try:
        subprocess.run(["gpasswd", "-a", "nobody", name], check=True, capture_output=True)
        yield name, grp.getgrnam(name).gr_gid, runs[0]
    finally:
        subprocess.run(["groupdel", name], capture_output=True)


def test_members_of_a_group_share_a_store_and_no_one_else_does(lab_group):
    """nobody (a member) makes the store and stores a result; root takes it (the store's
    folder is nobody's, 2770, of the group), stores one of its own, which nobody
    takes; stored files are 0440, the group's; an account outside it is refused."""
    name, gid, python = lab_group
    base = Path(tempfile.mkdtemp(prefix="hertzchain-group-", dir="/tmp"))
    try:
        os.chmod(base, 0o755)
        shared = base / "lab" / "store"  # in a folder of nobody's, a member
        for folder in ("nobody", "root", "lab"):
            (base / folder).mkdir()
        shutil.chown(base / "nobody", "nobody")
        shutil.chown(base / "lab", "nobody")
        (base / "nobody" / "table.csv").write_text("nobody's\n")
        made = as_account(
            65534, [gid], str(shared), name, "put", KEY, f"{base}/nobody/table.csv", python=python
        )
        assert made.returncode == 0, made.stderr
        info = shared.stat()
        assert (info.st_uid, info.st_gid, stat.S_IMODE(info.st_mode)) == (65534, gid, 0o2770)
        store = Store.open({STORE_VARIABLE: str(shared), GROUP_VARIABLE: name})
        assert store.fetch(KEY, [str(base / "root" / "taken.csv")]) == json.loads(made.stdout)
        assert (base / "root" / "taken.csv").read_text() == "nobody's\n"
        (base / "root" / "table.csv").write_text("root's\n")
        store.put(OTHER, [str(base / "root" / "table.csv")], {"run": "root's"})
        taken = as_account(
            65534, [gid], str(shared), name, "fetch", OTHER, f"{base}/nobody/t.csv", python=python
        )
        assert taken.returncode == 0, taken.stderr
        assert (base / "nobody" / "t.csv").read_text() == "root's\n"
        for path in [shared, *shared.rglob("*")]:
            info = path.lstat()
            assert info.st_gid == gid and not info.st_mode & 0o007, path  # never everyone
            if path.is_file():
                assert stat.S_IMODE(info.st_mode) == 0o440, path  # never writable once stored
        outside = as_account(
            54321, [], str(shared), name, "fetch", KEY, f"{base}/x.csv", python=python
        )
        assert outside.returncode == 1 and "refused" in outside.stderr
        assert f"not a member of group {name}" in outside.stderr
    finally:
        shutil.rmtree(base)


# ---- flushed to disk, and clean after a kill ------------------------------------------


def _path_of(fd: int) -> str:
    return os.readlink(PROC_FD / str(fd))


@pytest.fixture
def disk_events(monkeypatch) -> list[tuple[str, str]]:
    """Every fsync ("sync", path) and rename ("rename", source path) from now on."""
    if not PROC_FD.is_dir():
        pytest.skip("needs /proc/self/fd to name what a descriptor is")
    events: list[tuple[str, str]] = []
    fsync, rename, replace = os.fsync, os.rename, os.replace

    def syncing(fd):
        events.append(("sync", _path_of(fd)))
        fsync(fd)

    def renaming(real):
        def call(source, target, *, src_dir_fd=None, dst_dir_fd=None):
            where = _path_of(src_dir_fd) if src_dir_fd is not None else ""
            events.append(("rename", os.path.join(where, os.fspath(source))))
            real(source, target, src_dir_fd=src_dir_fd, dst_dir_fd=dst_dir_fd)

        return call

    monkeypatch.setattr(os, "fsync", syncing)
    monkeypatch.setattr(os, "rename", renaming(rename))
    monkeypatch.setattr(os, "replace", renaming(replace))
    return events


def flushed_before_renamed(events, source: str, names: list[str]) -> bool:
    """Whether each of ``names`` (paths below ``source``, "" for itself) was flushed
    before ``source`` was renamed."""
    (at,) = [i for i, event in enumerate(events) if event == ("rename", source)]
    synced = {path for kind, path in events[:at] if kind == "sync"}
    return all(os.path.join(source, name).rstrip("/") in synced for name in names)


def test_put_flushes_every_stored_file_and_folder_before_the_rename(store, outputs, disk_events):
    store.put(KEY, outputs, {})
    (staging,) = [p for kind, p in disk_events if kind == "rename" and PREFIX in p]
    entry = store.entry(KEY)
    names = ["", *(str(p.relative_to(entry)) for p in entry.rglob("*"))]
    assert len(names) == 8  # the entry, files/, files/0, files/1/, two files, sub/, manifest
    assert flushed_before_renamed(disk_events, staging, names)
    assert disk_events[-1] == ("sync", str(entry.parent))  # the rename itself


def test_fetch_flushes_each_copy_before_its_rename(store, outputs, tmp_path, disk_events):
    store.put(KEY, outputs, {})
    disk_events.clear()
    again = elsewhere(outputs, tmp_path)
    store.fetch(KEY, again)
    copies = [p for kind, p in disk_events if kind == "rename"]
    assert len(copies) == 2
    for copy, out in zip(copies, again):
        names = ["", *(str(p.relative_to(out)) for p in Path(out).rglob("*"))]
        assert flushed_before_renamed(disk_events, copy, names)
    assert disk_events[-1] == ("sync", str(Path(again[1]).parent))


def test_the_atomic_writers_flush_before_they_rename(tmp_path, disk_events):
    atomic.write_text_atomic("x\n", tmp_path / "a.txt")
    ((_, temporary),) = [event for event in disk_events if event[0] == "rename"]
    assert flushed_before_renamed(disk_events, temporary, [""])
    assert disk_events[-1] == ("sync", str(tmp_path))
    staging = tmp_path / "staging"
    staging.mkdir()
    disk_events.clear()
    atomic.replace_folder(staging, tmp_path / "dataset")
    assert flushed_before_renamed(disk_events, str(staging), [""])


STOPPED = textwrap.dedent("""
    import os, signal, sys
    from chain.pipeline.run import store, store_files as module
    root, how, key, *outputs = sys.argv[1:]
    check, calls = module.check_file, []

    def stopping(*args):
        got = check(*args)
        calls.append(got)
        if len(calls) == 2:  # the table copied, the dataset half copied
            os.kill(os.getpid(), getattr(signal, how))
        return got

    module.check_file = stopping
    store.Store.open({"HERTZCHAIN_STORE": root}).fetch(key, outputs)
""")


@pytest.mark.parametrize("how", ["SIGKILL", "SIGTERM", "SIGINT"])
def test_a_stopped_fetch_leaves_nothing_for_long(store, outputs, tmp_path, how):
    """A fetch stopped half way: by SIGTERM or SIGINT, its staged copies are removed as
    it stops; by SIGKILL, they stay until the next fetch into that folder (or a Store
    opened over its store) removes them. No output is half there."""
    store.put(KEY, outputs, {})
    again = elsewhere(outputs, tmp_path)
    run = tmp_path / "results" / "second"
    stopped = subprocess.run(
        [sys.executable, "-c", STOPPED, str(store.root), how, KEY, *again],
        capture_output=True, text=True, stdin=subprocess.DEVNULL,
    )  # fmt: skip
    signum = getattr(signal, how)
    assert stopped.returncode in (-signum, 128 + signum), stopped.stderr
    assert not any(Path(p).exists() for p in again)
    left = staging_left(run)
    assert bool(left) == (how == "SIGKILL")
    assert store.fetch(KEY, again) is not None
    assert staging_left(run) == []


def test_only_staging_of_processes_gone_is_stale(tmp_path):
    """A staging name of a live process, or of another machine, is left alone."""
    host = os.uname().nodename
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True).stdout.strip()  # fmt: skip
    names = {
        "dead": f"{PREFIX}00-{gone}-{host}",
        "alive": f"{PREFIX}01-{os.getpid()}-{host}",
        "elsewhere": f"{PREFIX}02-{gone}-another-{host}",
        "unrelated": ".pulses.csv.0a1b2c3d",
    }
    for name in names.values():
        (tmp_path / name).mkdir()
    (tmp_path / names["dead"] / "file").write_text("x")
    assert remove_stale_staging(tmp_path) == [names["dead"]]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        name for kind, name in names.items() if kind != "dead"
    )
    assert remove_stale_staging(tmp_path / "missing") == []


# ---- hertzchain store -------------------------------------------------------------------


@pytest.fixture
def shelf(tmp_path, monkeypatch):
    """A checkout with a store of three entries: one that the run folder ``paper``
    shows (stored 2020-01-01), one whose file the run shows with other bytes, one of
    a run folder without SHA256SUMS. Returns the store and the keys in that order."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(STORE_VARIABLE, raising=False)
    store = Store.open({})
    keys = ["a1" * 32, "b2" * 32, "c3" * 32]
    for run, key, stored in [("paper", keys[0], "2020-01-01T10:00:00"),
                             ("paper", keys[1], "2024-06-01T10:00:00"),
                             ("gone", keys[2], "2024-06-01T10:00:00")]:  # fmt: skip
        folder = tmp_path / "results" / run
        (folder / "raw").mkdir(parents=True, exist_ok=True)
        (folder / "raw" / f"{key[:2]}.csv").write_text(f"{key}\n")
        (folder / f"{key[:2]}.csv").write_text(f"{key[:2]}\n")
        paths = [f"{key[:2]}.csv", "raw"]
        store.put(key, [str(folder / p) for p in paths], {"paths": paths, "stored": stored})
    (tmp_path / "results" / "paper" / "b2.csv").write_text("changed\n")
    write_checksums(tmp_path / "results" / "paper")
    return store, keys


def entries_left(store: Store) -> list[str]:
    return [key for key, _, _ in store.entries()]


def test_store_says_where_it_is_how_many_entries_and_their_size(shelf, capsys):
    store, _ = shelf
    size = sum(size for _, _, size in store.entries())
    assert main(["store"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"result store {Path('results') / '.store'}: 3 entries, ")
    assert f"({size} bytes)" in out or f"{size} B" in out


def test_prune_removes_what_no_run_folder_holds(shelf, capsys):
    """The run folder shows the first entry's every file with its digest: kept; the
    second's file has other bytes, the third's run folder has no SHA256SUMS: gone."""
    store, keys = shelf
    assert main(["store", "prune", "--dry-run"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert entries_left(store) == keys  # nothing removed by a dry run
    assert [line.split()[0] for line in out[:-1]] == [keys[1][:12], keys[2][:12]]
    freed = sum(size for key, _, size in store.entries() if key != keys[0])
    assert out[-1].startswith("would remove 2 entries, freeing ") and str(freed) in out[-1]
    assert main(["store", "prune"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == out[-1].replace(
        "would remove 2 entries, freeing", "removed 2 entries, freed"
    )
    assert entries_left(store) == keys[:1]
    assert list((store.root / "tmp").iterdir()) == []


def test_prune_older_than_removes_entries_stored_before_the_day_even_held(shelf, capsys):
    store, keys = shelf
    assert main(["store", "prune", "--older-than", "2019-12-31"]) == 0
    assert entries_left(store) == keys[:1]
    assert main(["store", "prune", "--older-than", "2020-01-02"]) == 0
    assert "stored 2020-01-01, before 2020-01-02" in capsys.readouterr().out
    assert entries_left(store) == []


def test_store_honours_its_variable_and_creates_nothing(tmp_path, monkeypatch, outputs, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "elsewhere"))
    assert main(["store"]) == 0 and main(["store", "prune"]) == 0
    assert capsys.readouterr().out == f"no result store at {tmp_path / 'elsewhere'}\n" * 2
    assert not (tmp_path / "elsewhere").exists()
    Store.open(os.environ).put(KEY, outputs, {"stored": datetime.datetime.now().isoformat()})
    assert main(["store"]) == 0
    assert capsys.readouterr().out.startswith(f"result store {tmp_path / 'elsewhere'}: 1 entries")
    os.chmod(tmp_path / "elsewhere", 0o777)
    assert main(["store"]) == 2
    assert "writable by others" in capsys.readouterr().err
