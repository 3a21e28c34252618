"""The benchmarks' figures come from the benchmarks: each writes its results
file under benchmarks/results/ and, at once, regenerates the table of
benchmarks/README.md from all those files (``measure.write_result``; also
``python benchmarks/table.py``). Nothing here runs a benchmark."""

from __future__ import annotations

import importlib.util
import json
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"


def _load(name: str, alias: str):
    """benchmarks/<name>.py as the module ``alias``."""
    spec = importlib.util.spec_from_file_location(alias, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[alias] = module  # for its dataclasses
    spec.loader.exec_module(module)
    return module


measure = _load("measure", "measure")  # as the benchmarks and table.py import it
RESULT_FILES = sorted(measure.RESULTS.glob("*.json"))


def test_the_readme_table_is_generated_from_the_results_files():
    readme = measure.README.read_text(encoding="utf-8")
    expected = measure.table(measure.read_results())
    assert measure.readme_table(readme) == expected, (
        "benchmarks/README.md's table differs from benchmarks/results/*.json: "
        "run  python benchmarks/table.py"
    )


def test_there_are_results():
    assert RESULT_FILES, "no results file under benchmarks/results/"


@pytest.mark.parametrize("path", RESULT_FILES, ids=lambda path: path.name)
def test_each_results_file_says_what_where_and_when(path):
    result = json.loads(path.read_text(encoding="utf-8"))
    assert tuple(result) == measure.RESULT_KEYS
    assert result["benchmark"] == path.stem
    assert result["command"].startswith("python benchmarks/")
    assert result["date_utc"].endswith("Z")
    assert isinstance(result["dirty"], bool) and result["commit"]
    assert set(result["machine"]) == {"cpu", "cores", "python", "numpy", "numba"}
    assert {"cores", "before", "after"} <= set(result["load_average"])
    assert isinstance(result["loaded"], bool)
    assert result["figures"]
    for figure in result["figures"]:
        assert tuple(figure) == measure.FIGURE_KEYS
        assert figure["name"] and figure["bounded_by"], figure
        assert figure["value"] is None or isinstance(figure["value"], int | float)
        if result["loaded"] and figure["unit"] not in measure.LOAD_INDEPENDENT_UNITS:
            assert "met" not in figure["verdict"].replace("not met", ""), (
                f"{figure['name']}: 'met' on a loaded machine"
            )


def test_every_benchmark_writes_its_results():
    scripts = [*sorted(BENCHMARKS.glob("bench_*.py")), BENCHMARKS / "kernel_breakdown.py"]
    silent = [s.name for s in scripts if "write_result(" not in s.read_text(encoding="utf-8")]
    assert not silent, f"benchmarks that write no results file: {silent}"


def test_write_result_refuses_met_under_load(tmp_path):
    """A figure judged "met" while other processes took the CPU is written as under load;
    a peak memory keeps its verdict. Results written elsewhere than benchmarks/results/
    go in no README unless one is given: the committed one is left as it was."""
    committed = measure.README.read_bytes()
    conditions = measure.Conditions(cores=2, loads=[0.5, 0.6], labels=["before", "after"])
    figures = [
        measure.Figure("speed", 1.1, "x", "the steps", "C", "<= 1.3", "met"),
        measure.Figure("memory", 250.0, "MB", "the record", None, "< 300 MB", "met"),
    ]
    path = measure.write_result("bench_x", figures, conditions, 0.5, folder=tmp_path)
    written = json.loads(path.read_text())
    assert written["loaded"] is True
    assert [f["verdict"] for f in written["figures"]] == [measure.UNDER_LOAD, "met"]
    quiet = measure.write_result("bench_x", figures, conditions, 0.01, folder=tmp_path)
    assert [f["verdict"] for f in json.loads(quiet.read_text())["figures"]] == ["met", "met"]
    text = measure.table(measure.read_results(tmp_path))
    assert "| bench_x | speed | 1.1 x | C | <= 1.3 | met | the steps |" in text
    assert measure.README.read_bytes() == committed


def test_a_benchmarks_run_leaves_the_readme_table_equal_to_the_results(tmp_path, monkeypatch):
    """What a benchmark does, on a copy of benchmarks/: write_result with its defaults
    rewrites a results file, and the README's table is that of the results files at
    once, so the first test above still passes; its text around the table is kept, and
    ``python benchmarks/table.py`` then finds nothing to change."""
    results, readme = tmp_path / "results", tmp_path / "README.md"
    names = sorted(p.name for p in measure.RESULTS.glob("*.json"))
    shutil.copytree(measure.RESULTS, results)
    shutil.copy(measure.README, readme)
    monkeypatch.setattr(measure, "RESULTS", results)
    monkeypatch.setattr(measure, "README", readme)
    before = readme.read_text(encoding="utf-8")
    conditions = measure.Conditions(cores=2, loads=[0.1, 0.2], labels=["before", "after"])
    figure = measure.Figure("speed-up, 2 threads / 1", 1.5, "x", "the cores' share", None)
    path = measure.write_result("bench_sweep", [figure], conditions, 0.01)
    assert path == results / "bench_sweep.json"
    after = readme.read_text(encoding="utf-8")
    assert after != before and "| bench_sweep | speed-up, 2 threads / 1 | 1.5 x |" in after
    assert measure.readme_table(after) == measure.table(measure.read_results(results))
    start, end = (before.index(marker) for marker in (measure.TABLE_BEGIN, measure.TABLE_END))
    assert after.startswith(before[:start]) and after.endswith(before[end:])
    assert not measure.write_table(readme, results)
    assert not list(results.glob(".*.tmp")) and not list(tmp_path.glob(".*.tmp"))
    assert sorted(p.name for p in results.glob("*.json")) == names  # no file left over
