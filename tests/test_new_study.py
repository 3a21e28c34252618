"""A new study in four places, as docs/architecture.md's worked example adds it ("A new
study, from nothing to the summary"): the mean crossing delay per model and chain,
``delay_mean``.

In a copy of the tiny run (conftest.py's ``tiny_run``: its checkout, its library in
src/, its results and store, Snakemake's records), the test writes

1. the library module ``src/chain/studies/delay_mean.py`` (:data:`LIBRARY`),
2. the script ``workflow/scripts/delay_mean.py`` (:data:`SCRIPT`),
3. the rule file ``workflow/rules/delay_mean.smk`` (:data:`RULES`), included in the
   Snakefile before report.smk (:data:`INCLUDE`),
4. the switch ``studies.delay_mean`` in workflow/schemas/config.schema.yaml, under
   ``studies.properties`` (:data:`SWITCH`),

then checks that a dry run lists the rule and nothing else computes but the study's job,
the summary, the article and the run folder; that after the run the table is in the run
folder and summary.json has the study's section (its rows); and that a run with the
switch off has neither. :func:`test_the_worked_example_is_the_documented_one` keeps the
snippets of the doc and these the same text.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "configs" / "tiny.yaml"
#: Longest a Snakemake call may take, s: a guard against a hang.
TIMEOUT = 1200

#: (1) The study's function, of plain arguments: a table in, a table out.
LIBRARY = '''\
"""The mean crossing delay per model and chain (docs/architecture.md's worked example
of a study)."""

import pandas as pd


def delay_mean(delays: pd.DataFrame) -> pd.DataFrame:
    """The mean ``delay_us`` of the ``ok`` rows of ``delays`` (tables/delays.csv), one
    row per source, model and N."""
    ok = delays[delays["ok"]]
    return ok.groupby(["source", "model", "N"], as_index=False)["delay_us"].mean()
'''

#: (2) Its script: read the inputs, call the function, write the output, seal.
SCRIPT = '''\
"""Mean crossing delay per model and chain (chain.studies.delay_mean)."""
import pandas as pd
from _logging import done, start
from chain.atomic import write_csv_atomic
from chain.studies.delay_mean import delay_mean

log = start(snakemake)
write_csv_atomic(delay_mean(pd.read_csv(snakemake.input.delays)), snakemake.output.table)
done(snakemake)
'''

#: (3) Its rule file: the rule written out, what goes in the run folder and summary.json.
RULES = """\
rule delay_mean:
    input:
        delays=made("delay_fits", "delays"),
    output:
        table=stored("delay_mean", "tables/delay_mean.csv"),
        sums=stored("delay_mean", "SHA256SUMS"),
    log:
        stored("delay_mean", "log"),
    conda:
        ENV
    script:
        "../scripts/delay_mean.py"


if PLAN.study("delay_mean"):
    publish("tables/delay_mean.csv", "delay_mean", "table")
    summarise(
        "delay_mean",
        "chain.report.numbers.summary:table_section",
        table=("delay_mean", "table", {}),
    )
"""

#: (3) ... and its line in the Snakefile, before report.smk's.
INCLUDE = 'include: "workflow/rules/delay_mean.smk"'
REPORT_INCLUDE = 'include: "workflow/rules/report.smk"'

#: (4) Its switch, under ``studies.properties`` of the schema.
SWITCH = """\
delay_mean:
  type: boolean
  default: true
  description: The mean crossing delay per model and chain (tables/delay_mean.csv).
"""


def started(output: str) -> set[str]:
    """The rules of the jobs Snakemake started (or, dry, would start)."""
    return set(re.findall(r"^(?:local)?rule (\w+):$", output, re.M)) - {"all"}


def add_study(work: Path) -> None:
    """The four places of the worked example, in the checkout ``work``."""
    (work / "src" / "chain" / "studies" / "delay_mean.py").write_text(LIBRARY)
    (work / "workflow" / "scripts" / "delay_mean.py").write_text(SCRIPT)
    (work / "workflow" / "rules" / "delay_mean.smk").write_text(RULES)
    snakefile = work / "Snakefile"
    text = snakefile.read_text()
    assert text.count(REPORT_INCLUDE) == 1, "the Snakefile includes report.smk once"
    snakefile.write_text(text.replace(REPORT_INCLUDE, f"{INCLUDE}\n{REPORT_INCLUDE}"))
    schema = work / "workflow" / "schemas" / "config.schema.yaml"
    lines = schema.read_text().splitlines(keepends=True)
    studies = lines.index("  studies:\n")
    at = next(n for n in range(studies, len(lines)) if lines[n] == "    properties:\n") + 1
    lines[at:at] = [f"      {line}" for line in SWITCH.splitlines(keepends=True)]
    schema.write_text("".join(lines))


def snakemake(work: Path, env: dict, *args: str) -> subprocess.CompletedProcess:
    result = subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "2", "--configfile", str(TINY), *args],
        cwd=work,
        env=env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=TIMEOUT,
    )
    assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]
    return result


@pytest.mark.workflow
@pytest.mark.heavy(cpu_s=6)
def test_a_new_study_in_four_places(tiny_run, tmp_path):
    """The study added to a copy of the tiny run: a dry run lists its rule; the run
    computes only its job, the summary, the article and the run folder; the table is
    in the run folder (checked by SHA256SUMS) and summary.json has its section, the
    table's rows; with the switch off, a run makes neither and says it did not run."""
    work = tmp_path / "checkout"
    shutil.copytree(tiny_run, work, symlinks=True, copy_function=shutil.copy2)
    env = {**os.environ, "PYTHONPATH": str(work / "src")}
    env.pop("NUMBA_CACHE_DIR", None)
    add_study(work)

    dry = snakemake(work, env, "--dry-run")
    assert started(dry.stdout + dry.stderr) == {
        "delay_mean", "summary", "article", "run_folder"
    }, dry.stdout[-3000:]  # fmt: skip
    run = snakemake(work, env)
    assert started(run.stdout + run.stderr) == started(dry.stdout + dry.stderr), run.stdout[-3000:]

    out = work / "results" / "tiny"
    table = pd.read_csv(out / "tables" / "delay_mean.csv")
    assert list(table.columns) == ["source", "model", "N", "delay_us"]
    assert set(table["model"]) == {"elastic", "viscoelastic", "virtual"}
    assert (table["delay_us"] < 0).all()  # the crossed wave arrives early
    summary = json.loads((out / "summary.json").read_text())
    assert summary["delay_mean"]["table"] == json.loads(table.to_json(orient="records"))
    assert "delay_mean" not in summary.get("studies_not_run", [])
    assert "  tables/delay_mean.csv\n" in (out / "SHA256SUMS").read_text()
    check = subprocess.run(
        ["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=out, capture_output=True, text=True
    )
    assert check.returncode == 0, check.stdout + check.stderr

    # The switch off, in a run of its own name: no job, no table, no section.
    off = tmp_path / "off.yaml"
    off.write_text("run_name: no_delay_mean\nstudies:\n  delay_mean: false\n")
    dry = snakemake(work, env, str(off), "--dry-run")
    assert "delay_mean" not in started(dry.stdout + dry.stderr), dry.stdout[-3000:]
    snakemake(work, env, str(off))
    out = work / "results" / "no_delay_mean"
    assert (out / "summary.json").is_file() and not (out / "tables" / "delay_mean.csv").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert "delay_mean" not in summary
    assert "delay_mean" in summary["studies_not_run"]


def test_the_worked_example_is_the_documented_one():
    """Each snippet of docs/architecture.md's worked example (the script, the rule file,
    the schema's switch, the Snakefile's line) is the text this test adds."""
    doc = (ROOT / "docs" / "architecture.md").read_text()
    section = doc[doc.index("### A new study") :]
    section = section[: section.index("\n### ", 1)]
    blocks = [
        textwrap.dedent(block) + "\n"
        for block in re.findall(r"```\w*\n(.*?)\n *```", section, re.S)
    ]
    for name, snippet in (("script", SCRIPT), ("rules", RULES), ("switch", SWITCH)):
        assert snippet in blocks, (
            f"docs/architecture.md's {name} snippet is not this test's {name.upper()} "
            "(tests/test_new_study.py): make them the same text"
        )
    assert f"`{INCLUDE}`" in " ".join(section.split()), "the Snakefile's include line"
    assert "`src/chain/studies/delay_mean.py`: `def delay_mean(delays)`" in section
