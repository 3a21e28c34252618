"""Bad input through Snakemake itself: a few representative cases, the rest
are in test_bad_configs.py and test_bad_datasets.py through the same library checks.

Each run uses an overlay in a temporary folder with its own run_name, in this checkout
(the checks stop Snakemake while it parses the Snakefile, before it locks or writes):
the console (Snakemake's stderr) must name the key or file, and results/<run>/ must not
exist afterwards. A run of the tiny config in a folder of its own shows that a bad
config writes nothing at all there: no run folder, no store.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "tests" / "data" / "virtual_small"
TINY = ROOT / "tests" / "configs" / "tiny.yaml"

pytestmark = pytest.mark.workflow


def run(tmp_path: Path, name: str, overlay: str, *args: str) -> tuple[int, str]:
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"run_name: {name}\n{overlay}")
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "1", "--configfile", str(path), *args],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
        stdin=subprocess.DEVNULL,
    )
    assert not (ROOT / "results" / name).exists(), f"results/{name}/ was written"
    return result.returncode, result.stdout + result.stderr


@pytest.mark.parametrize("args", [("--dry-run",), ()], ids=["dry-run", "real run"])
def test_nan_config_key_stops_before_any_job(tmp_path, args):
    status, console = run(
        tmp_path, "bad_nan_launch", "launch: {v0_min_m_s: .nan, v0_max_m_s: 1.0, count: 3}\n", *args
    )
    assert status != 0
    assert "config key 'launch.v0_min_m_s': nan is not a finite number" in console


def test_bad_dataset_is_listed_on_the_console_before_any_job(tmp_path):
    folder = tmp_path / "lab"
    shutil.copytree(EXAMPLE, folder)
    for name, line in (("shot_0001.csv", 57), ("shot_0004.csv", 9)):
        lines = (folder / name).read_text().splitlines()
        lines[line - 1] = lines[line - 1].split(",")[0] + ",abc,0"
        (folder / name).write_text("\n".join(lines) + "\n")
    status, console = run(
        tmp_path,
        "bad_dataset",
        f"experiment: {{source: measured, datasets: ['{folder}']}}\n"
        "chains: [{N: 25, sensors: [9, 17]}]\n",
    )
    assert status != 0
    assert f"{folder}/shot_0001.csv line 57: column bead9_V: 'abc' is not a number" in console
    assert f"{folder}/shot_0004.csv line 9: column bead9_V: 'abc' is not a number" in console
    assert "Error in rule" not in console  # stopped while the DAG was built, not in a job


def test_overlay_with_a_repeated_key_names_file_and_line(tmp_path):
    status, console = run(tmp_path, "bad_repeat", "seed: 1\nseed: 2\n", "--dry-run")
    assert status != 0
    assert f"{tmp_path}/bad_repeat.yaml line 3" in console
    assert "'seed' is given twice" in console


@pytest.mark.parametrize("args", [("--dry-run",), ()], ids=["dry-run", "real run"])
def test_a_chain_too_short_for_the_long_chains_stops_before_any_job(tmp_path, args):
    """``long_chains: {N: [3]}`` over the tiny config, in a working folder of its own:
    the console names the key and its bound (26, the shortest elastic chain whose SSW
    separates), no job is started or planned, and nothing is written: no run folder,
    no store."""
    work = tmp_path / "work"
    work.mkdir()
    overlay = tmp_path / "short.yaml"
    overlay.write_text("run_name: short\nlong_chains: {N: [3]}\n")
    configs = [str(ROOT / "config.yaml"), str(TINY), str(overlay)]
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "--snakefile", str(ROOT / "Snakefile"),
         "--directory", str(work), "--cores", "1", "--configfile", *configs, *args],
        cwd=work, capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL,
    )  # fmt: skip
    console = result.stdout + result.stderr
    assert result.returncode != 0, console[-3000:]
    assert "long_chains" in console and "26" in console, console[-3000:]
    assert not re.search(r"^(?:local)?rule \w+:$", console, re.M), console[-3000:]
    assert not (work / "results").exists()
