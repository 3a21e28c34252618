"""The benchmarks' figures come from the benchmarks (issue 55): each writes its results
file under benchmarks/results/ (``measure.write_result``), and the table of
benchmarks/README.md is generated from those files (``python benchmarks/table.py``).
Nothing here runs a benchmark."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"
#: Benchmarks of issue 54's kernels work: they call write_result once that work lands.
PENDING: set[str] = set()


def _load(name: str, alias: str):
    """benchmarks/<name>.py as the module ``alias``."""
    spec = importlib.util.spec_from_file_location(alias, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[alias] = module  # for its dataclasses
    spec.loader.exec_module(module)
    return module


measure = _load("measure", "measure")  # as the benchmarks and table.py import it
table = _load("table", "benchmarks_table")
RESULT_FILES = sorted(measure.RESULTS.glob("*.json"))


def test_the_readme_table_is_generated_from_the_results_files():
    readme = table.README.read_text(encoding="utf-8")
    expected = table.table(measure.read_results())
    assert table.readme_table(readme) == expected, (
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
    assert set(silent) <= PENDING, f"benchmarks that write no results file: {silent}"


def test_write_result_refuses_met_under_load(tmp_path):
    """A figure judged "met" while other processes took the CPU is written as under load;
    a peak memory keeps its verdict."""
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
    text = table.table(measure.read_results(tmp_path))
    assert "| bench_x | speed | 1.1 x | C | <= 1.3 | met | the steps |" in text
