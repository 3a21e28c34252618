"""The workflow as a Snakemake module: a lab's own Snakefile, in a folder of its own,
uses this checkout's with a local path,

    configfile: "my_config.yaml"
    module hertzchain:
        snakefile: "<checkout>/Snakefile"
        config: config
    use rule * from hertzchain as hertzchain_*

with its own config (config.yaml's content with the tiny run's overlay merged onto it,
and a run name of its own). Its results go under its own working directory
(``results/<run_name>/``, the store in its ``results/.store``) and nothing is written
in the checkout (Python's and numba's caches aside, ``__pycache__``).

The checkout is a copy of the tiny run's (conftest.py's ``tiny_run``: Snakefile,
workflow/, profiles/, config.yaml and the library in src/, without its results). The
lab's store starts as a copy of the tiny run's without the entries of ``delay_fits``
and of every job after it (as if the lab had run the tiny run before, then changed
the fit): its run computes those jobs through the module, and finds the others in its
store, which it can only if the module gives every job the recipe a plain run gives
it. A dry run of everything (``--forceall``) lists every rule of the workflow, and the
HTML report is made in the lab's folder too.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "configs" / "tiny.yaml"
#: The lab's run name.
RUN = "lab"
#: Longest a Snakemake call may take, s: a guard against a hang.
TIMEOUT = 1200
#: An entry of the store: rule, wildcards' label, key (chain.pipeline.run.entries).
ENTRY = re.compile(r"^(?P<rule>[A-Za-z_]\w*)(?:-(?P<label>.+))?-(?P<key>[0-9a-f]{32})$")
#: What the checkout is made of (tests/conftest.py's tiny_run copies the same).
CHECKOUT_PARTS = ("Snakefile", "config.yaml", "workflow", "profiles", "src")

LAB_SNAKEFILE = """\
configfile: "my_config.yaml"


module hertzchain:
    snakefile:
        "{checkout}/Snakefile"
    config:
        config


use rule * from hertzchain as hertzchain_*
"""


def merged(base: dict, overlay: dict) -> dict:
    """``overlay`` merged onto ``base`` as Snakemake merges config files (mappings
    merged, anything else replaced)."""
    result = dict(base)
    for key, value in overlay.items():
        if isinstance(value, dict) and isinstance(result.get(key), dict):
            result[key] = merged(result[key], value)
        else:
            result[key] = value
    return result


def files_of(folder: Path) -> dict[str, tuple[int, int, int]]:
    """Every file and folder below ``folder`` but Python's caches: path -> (mode, size,
    modification time)."""
    found = {}
    for path in sorted(folder.rglob("*")):
        if "__pycache__" in path.parts:
            continue
        info = path.lstat()
        found[str(path.relative_to(folder))] = (info.st_mode, info.st_size, info.st_mtime_ns)
    return found


def downstream(store: Path, rule: str) -> set[str]:
    """The entries of ``rule`` and of every job that read them, at any remove, as the
    entries' SHA256SUMS list what each job read (``../<entry>/<file>``)."""
    reads = {}
    for entry in store.iterdir():
        if ENTRY.match(entry.name) and (entry / "SHA256SUMS").is_file():
            lines = (entry / "SHA256SUMS").read_text().splitlines()
            reads[entry.name] = {
                line.split("  ../")[1].split("/")[0] for line in lines if "  ../" in line
            }
    found = {name for name in reads if ENTRY.match(name)["rule"] == rule}
    while more := {name for name, inputs in reads.items() if inputs & found} - found:
        found |= more
    return found


def started(output: str) -> set[str]:
    """The rules of the jobs Snakemake started (or, dry, would start)."""
    return set(re.findall(r"^(?:local)?rule (\w+):$", output, re.M)) - {"hertzchain_all"}


@pytest.mark.workflow
@pytest.mark.heavy(cpu_s=5)
def test_a_lab_uses_the_workflow_as_a_module(tiny_run, tmp_path, env_of_library):
    """The lab's run computes, through the module, the jobs its store lacks, and finds
    the others stored under the keys a plain run gave them; its run folder is in its
    own folder and checks; a dry run of everything lists every rule; the report is
    made there too; the checkout is as it was."""
    checkout, lab = tmp_path / "hertzchain", tmp_path / "lab"
    checkout.mkdir()
    for name in CHECKOUT_PARTS:
        source = tiny_run / name
        if source.is_dir():
            shutil.copytree(source, checkout / name, symlinks=True, copy_function=shutil.copy2)
        else:
            shutil.copy2(source, checkout / name)
    env = env_of_library(checkout / "src")

    lab.mkdir()
    (lab / "Snakefile").write_text(LAB_SNAKEFILE.format(checkout=checkout))
    config = merged(
        yaml.safe_load((ROOT / "config.yaml").read_text()), yaml.safe_load(TINY.read_text())
    )
    (lab / "my_config.yaml").write_text(
        yaml.safe_dump({**config, "run_name": RUN}, sort_keys=False)
    )
    store = lab / "results" / ".store"
    shutil.copytree(
        tiny_run / "results" / ".store", store, symlinks=True, copy_function=shutil.copy2
    )
    removed = downstream(store, "delay_fits")
    for name in removed:
        shutil.rmtree(store / name)
    before = files_of(checkout)

    def snakemake(*args: str) -> subprocess.CompletedProcess:
        result = subprocess.run(
            [sys.executable, "-m", "snakemake", *args],
            cwd=lab,
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=TIMEOUT,
        )
        assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]
        return result

    run = snakemake("--cores", "2")
    computed = {f"hertzchain_{ENTRY.match(name)['rule']}" for name in removed}
    assert "hertzchain_delay_fits" in computed and "hertzchain_summary" in computed, removed
    assert started(run.stdout + run.stderr) == computed | {"hertzchain_run_folder"}, run.stdout[
        -3000:
    ]

    out = lab / "results" / RUN
    assert json.loads((out / "summary.json").read_text())["run_name"] == RUN
    for name in ("tables/delay_fits.csv", "tables/delays.csv", "figures/fig4_delay_vs_force.pdf"):
        assert (out / name).read_bytes() == (tiny_run / "results" / "tiny" / name).read_bytes(), (
            name
        )
    check = subprocess.run(
        ["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=out, capture_output=True, text=True
    )
    assert check.returncode == 0, check.stdout + check.stderr
    # The lab's store: the tiny run's entries, and those its jobs computed, sealed; the
    # fit's again under the tiny run's key (the same recipe, through the module).
    entries = {name for name in os.listdir(store) if ENTRY.match(name)}
    tiny = {name for name in os.listdir(tiny_run / "results" / ".store") if ENTRY.match(name)}
    new = entries - (tiny - removed)
    assert tiny - removed <= entries
    assert {n for n in removed if n.startswith("delay_fits-")} <= new, sorted(new)
    assert {f"hertzchain_{ENTRY.match(name)['rule']}" for name in new} == computed, sorted(new)
    assert all((store / name / "SHA256SUMS").is_file() for name in new), sorted(new)

    # Every rule of the workflow, through the module, dry: nothing written.
    dry = snakemake("--cores", "2", "--forceall", "--dry-run")
    rules = {f"hertzchain_{ENTRY.match(name)['rule']}" for name in entries}
    assert rules | {"hertzchain_run_folder"} <= started(dry.stdout + dry.stderr), dry.stdout[-3000:]

    snakemake("--report", "report.html")
    assert (lab / "report.html").stat().st_size > 0

    after = files_of(checkout)
    assert after == before, {
        "written": sorted(set(after) - set(before)),
        "removed": sorted(set(before) - set(after)),
        "changed": sorted(p for p in set(after) & set(before) if after[p] != before[p]),
    }
