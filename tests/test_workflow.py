"""The Snakemake pipeline end to end on a tiny config (tests/configs/tiny.yaml), built
once per session (conftest.py's ``tiny_run``) in a copy of the checkout: the run folder
``results/tiny/`` holds the contract files with their columns and checksums, the
virtual experiment runs through the acceptance protocol into Fig. 2 and the tables,
the HTML report shows every figure and the scripts' code, and the store
(``results/.store``) lets Snakemake alone decide what runs: a second run, a copied
checkout and a renamed run compute nothing of the results, an edit of the library
reruns what depends on it, a what-if's dry run lists exactly the jobs it then starts,
and ``-R``, ``--until``, ``--omit-from``, ``--forceall`` and ``--rerun-triggers
mtime`` do what Snakemake documents, leaving no stored result computed from a stale
one. A second tiny run (tests/configs/tiny_measured.yaml) reads the committed dataset
tests/data/virtual_small as a lab's measured dataset. The workflow is lint- and
format-clean.

Rule names are read off the workflow where a test can (the rule graph, the rule files,
the run folder's logs): rules merge and split as the workflow changes.
"""

from __future__ import annotations

import hashlib
import html
import json
import os
import re
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pandas as pd
import pytest

from chain.analysis.ssw_speed import SPEED_COLUMNS
from chain.analysis.ssw_track import TRACK_COLUMNS
from chain.pipeline.plan.code import script_sources
from chain.pipeline.run.entries import ENTRY
from chain.report.printed import plus_minus

ROOT = Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "configs" / "tiny.yaml"
TINY_MEASURED = ROOT / "tests" / "configs" / "tiny_measured.yaml"
DATASET = Path("tests") / "data" / "virtual_small"
SNAKEMAKE = [sys.executable, "-m", "snakemake"]

pytestmark = pytest.mark.workflow

#: Columns each contract table must have (results contract + docs/interfaces.md).
TABLE_COLUMNS = {
    "pulses": [
        "source", "model", "N", "shot", "kind", "amplitude", "sensor", "bead", "role",
        "wave", "estimator", "F_m_N", "T_s", "tau_s", "ok", "reason",
    ],
    "delays": [
        "source", "model", "N", "shot", "amplitude", "wave", "estimator", "F_m_N",
        "delay_us", "tof_crossed_us", "tof_reference_us", "ok", "reason",
    ],
    "delay_fits": [
        "source", "model", "N", "estimator", "C_us_N16", "C_stderr_us_N16", "exponent",
        "exponent_stderr", "n_points",
    ],
    "ssw": ["source", "model", "N", "shot", "amplitude", "sensor", "F_m_N", "ssw_N"],
    "ssw_fits": ["source", "model", "N", "slope", "slope_stderr", "n_points"],
}  # fmt: skip

#: Tables of the run as a whole (no source/model columns): C against our choices.
RUN_TABLE_COLUMNS = {
    "c_sensitivity": [
        "choice", "value", "N", "C", "C_stderr", "exponent", "exponent_stderr", "headline",
    ],
    "ablation_exponent": [
        "variant", "N", "C", "C_stderr", "exponent", "exponent_stderr",
    ],
}  # fmt: skip

#: The paper's figures: every run with an experiment draws them.
PAPER_FIGURES = (
    "fig1_setup", "fig2_experiment_traces", "fig3_simulation_traces", "fig4_delay_vs_force",
    "fig5_ssw_vs_force",
)  # fmt: skip

#: Library files that integrate a chain (our kernel or LAMMPS).
SIMULATION_CODE = ("physics/integrator.py", "physics/lammps_engine.py")

#: The rules that integrate a chain (our kernel or LAMMPS), of any config: those of the
#: tiny run are checked against the rule graph (:func:`simulations`). A rule whose script
#: only imports an integrating module (to read what a simulation recorded) is none.
SIMULATIONS = (
    "simulate", "long_chain", "virtual_experiment", "c_sensitivity_simulate", "lammps_check",
    "lammps_setting", "ablation_shots",
)  # fmt: skip

#: The run folder's files that state the run (its name, its config's hash); logs/,
#: benchmarks/ and SHA256SUMS too.
PER_RUN_FILES = {"summary.json", "summary.md", "article.pdf", "SHA256SUMS"}

#: Longest a Snakemake call may take, s: a guard against a hang, far above a tiny run's
#: minutes on a machine shared with other workers (pytest-xdist) or other work.
TIMEOUT = 1800


# ---- Snakemake in a work tree, and what it says ----------------------------------------


def run(args, work: Path, env: dict, timeout=TIMEOUT) -> subprocess.CompletedProcess:
    """Snakemake in ``work``, with the work tree's own Snakefile if it has one (a copied
    checkout), else the repository's; started in ``work``, as a user would, so that the
    workflow profile is the work tree's (profiles/default), wherever pytest started; no
    standard input."""
    snakefile = work / "Snakefile" if (work / "Snakefile").exists() else ROOT / "Snakefile"
    return subprocess.run(
        [*SNAKEMAKE, "--snakefile", str(snakefile), "--directory", str(work), *args],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        stdin=subprocess.DEVNULL,
    )


def succeeded(result: subprocess.CompletedProcess) -> str:
    """The console (stdout and stderr) of a Snakemake call that must have succeeded."""
    output = result.stdout + result.stderr
    assert result.returncode == 0, output[-5000:]
    return output


def tiny(*args: str) -> list[str]:
    """Snakemake's arguments for the tiny config (and overlays) with 2 cores."""
    return ["--cores", "2", "--configfile", str(TINY), *args]


#: A job as Snakemake prints it, run or (dry) planned: its rule and indented fields.
JOB = re.compile(r"^(?:local)?rule (\w+):\n((?:[ \t]+\S.*\n?)*)", re.M)


def jobs(output: str) -> Counter:
    """The jobs Snakemake started (or, dry, would start), as (rule, input, output)
    lines: the console's ``rule <name>:`` blocks."""
    found = Counter()
    for match in JOB.finditer(output):
        fields = dict(re.findall(r"^\s+(\w+): (.*)$", match[2], re.M))
        found[(match[1], fields.get("input", ""), fields.get("output", ""))] += 1
    return found


def started(output: str) -> set[str]:
    """The rules of the jobs Snakemake started (or would start), but ``all``."""
    return {rule for rule, _, _ in jobs(output)} - {"all"}


def planned(work: Path, env: dict, *args: str) -> Counter:
    """Rule -> number of jobs a dry run of the tiny config would start (none: {})."""
    output = succeeded(run(["-n", *tiny(*args)], work, env))
    return Counter(rule for (rule, _, _), n in jobs(output).items() for _ in range(n))


# ---- the tiny run and copies of it ------------------------------------------------------


def library_env(src: Path) -> dict:
    """The environment of a run whose jobs import the library in ``src``; the store the
    work tree's own (results/.store), numba's kernels in the library's folders."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    for name in ("NUMBA_CACHE_DIR", "HERTZCHAIN_STORE", "HERTZCHAIN_STORE_GROUP"):
        env.pop(name, None)
    return env


def checkout(work: Path) -> tuple[Path, Path, dict, Path]:
    """(work directory, run folder, env, library folder) of a tiny run's checkout: its
    jobs import the library copied into it (``src/chain``)."""
    return work, work / "results" / "tiny", library_env(work / "src"), work / "src" / "chain"


#: What Snakemake writes in a work tree as it reads it (a dry run, a report, the rule
#: graph: the shared tiny checkout's tests do, in another worker, as it is copied), and
#: decides nothing by: not copied.
_NOT_COPIED = shutil.ignore_patterns("log", "iocache")


def checkout_copy(work: Path, folder: Path) -> tuple[Path, Path, dict, Path]:
    """A copy of the tiny run's checkout in ``folder``, its store and Snakemake's records
    included (copy2 keeps the times that tell Snakemake what is up to date)."""
    copy = folder / "elsewhere" / "checkout"
    shutil.copytree(work, copy, symlinks=True, copy_function=shutil.copy2, ignore=_skipped)
    return checkout(copy)


def _skipped(folder: str, names: list[str]) -> set[str]:
    """:data:`_NOT_COPIED`, in the work tree's .snakemake/ only."""
    return _NOT_COPIED(folder, names) if Path(folder).name == ".snakemake" else set()


@pytest.fixture(scope="session")
def tiny_checkout(tiny_run):
    """The tiny run (conftest.py's ``tiny_run``: built once per test session with 2 cores
    in a copy of the checkout: Snakefile, workflow, config, library): (work directory,
    run folder, env, library folder). Shared by every test that asks for it, and by
    test_reproducibility.py: a test that runs jobs or edits works on a copy
    (:func:`checkout_copy`)."""
    return checkout(tiny_run)


def store_of(work: Path) -> Path:
    return work / "results" / ".store"


def entries(work: Path) -> dict[str, str]:
    """The store's entries: folder name -> rule."""
    store = store_of(work)
    return {p.name: m["rule"] for p in store.iterdir() if (m := ENTRY.match(p.name))}


def entry_of(work: Path, rule: str) -> Path:
    """The one entry of ``rule`` (a rule with one job) in the store."""
    (found,) = [store_of(work) / name for name, r in entries(work).items() if r == rule]
    return found


def stored_file(work: Path, pattern: str) -> Path:
    """The one stored file matching ``pattern`` (below an entry: ``*/simulation/x.csv``)."""
    (found,) = store_of(work).glob(pattern)
    return found


def listing(folder: Path) -> dict[str, tuple]:
    """Every path below ``folder`` (hidden ones too) -> (kind, size, mode, mtime)."""
    found = {}
    for path in [folder, *folder.rglob("*")]:
        info = path.lstat()
        kind = "dir" if path.is_dir() else "link" if path.is_symlink() else "file"
        size = 0 if kind == "dir" else info.st_size
        found[str(path.relative_to(folder))] = (kind, size, info.st_mode, info.st_mtime_ns)
    return found


def logged_jobs(out: Path) -> Counter:
    """Rule -> number of jobs whose log the run folder holds (``logs/<rule>.log``,
    ``logs/<rule>/<wildcards>.log``): every job upstream of its files."""
    logs = out / "logs"
    return Counter(p.relative_to(logs).parts[0].removesuffix(".log") for p in logs.rglob("*.log"))


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def differing_results(a: Path, b: Path, *, per_run: bool = False) -> list[str]:
    """Files of run folder ``a`` missing from ``b`` or with other bytes there, but its
    logs, benchmarks and SHA256SUMS; with ``per_run``, summary and article too."""
    skipped = {"SHA256SUMS"} if per_run else PER_RUN_FILES
    names = [
        p.relative_to(a)
        for p in sorted(a.rglob("*"))
        if p.is_file()
        and not {"logs", "benchmarks"} & set(p.relative_to(a).parts)
        and p.name not in skipped
    ]
    assert len(names) > 20, names  # tables, figures, the selection
    return [str(n) for n in names if not (b / n).is_file() or digest(a / n) != digest(b / n)]


def same_summary(a: Path, b: Path) -> bool:
    """summary.json of two runs equal but for the run's name and provenance."""
    first, second = (json.loads((folder / "summary.json").read_text()) for folder in (a, b))
    for summary in (first, second):
        summary.pop("run_name"), summary.pop("provenance")
    return first == second


def sealed_problems(work: Path) -> list[str]:
    """The entries of the store whose own SHA256SUMS ``sha256sum -c`` rejects: an output
    changed, or an input it read (``../<entry>/<file>``) that is no longer what it read."""
    bad = []
    for name in sorted(entries(work)):
        check = subprocess.run(
            ["sha256sum", "-c", "--quiet", "SHA256SUMS"],
            cwd=store_of(work) / name,
            capture_output=True,
            text=True,
            stdin=subprocess.DEVNULL,
        )
        if check.returncode:
            bad.append(f"{name}: {check.stdout}{check.stderr}")
    return bad


# ---- the rules, read off the workflow ------------------------------------------------


def rule_scripts(work: Path) -> dict[str, Path]:
    """Rule -> the script it runs, as the rule files of ``work`` write them."""
    scripts = {}
    for path in sorted((work / "workflow" / "rules").glob("*.smk")):
        for block in re.split(r"^(?=rule \w+:)", path.read_text(), flags=re.M)[1:]:
            script = re.search(r"^\s+script:\s*\n?\s*\"([^\"]+)\"", block, re.M)
            if script:
                scripts[re.match(r"rule (\w+):", block)[1]] = (path.parent / script[1]).resolve()
    return scripts


def rules_running(work: Path, *modules: str) -> set[str]:
    """The rules whose script runs one of the library files ``modules`` (relative to
    src/chain), read off the import statements as the recipes' keys read them."""
    package = (work / "src" / "chain").resolve()
    found = set()
    for rule, script in rule_scripts(work).items():
        sources = {os.path.abspath(p) for p in script_sources(script, package)}
        if any(str(package / module) in sources for module in modules):
            found.add(rule)
    return found


@pytest.fixture(scope="session")
def rule_graph(tiny_checkout) -> dict[str, set[str]]:
    """The tiny run's rules (``snakemake --rulegraph``): rule -> the rules that read its
    outputs."""
    work, _, env, _ = tiny_checkout
    output = succeeded(run(["--rulegraph", "--configfile", str(TINY)], work, env))
    names = dict(re.findall(r"^\s*(\d+)\[label = \"(\w+)\"", output, re.M))
    graph = {name: set() for name in names.values()}
    for source, target in re.findall(r"^\s*(\d+) -> (\d+)", output, re.M):
        graph[names[source]].add(names[target])
    assert {"simulate", "pulses", "run_folder", "all"} <= set(graph), graph
    return graph


def downstream(graph: dict[str, set[str]], *rules: str) -> set[str]:
    """The rules that read, directly or not, the outputs of ``rules``; not ``all``."""
    found, todo = set(), [child for rule in rules for child in graph[rule]]
    while todo:
        rule = todo.pop()
        if rule not in found:
            found.add(rule)
            todo += graph[rule]
    return found - {"all"}


def upstream(graph: dict[str, set[str]], rule: str) -> set[str]:
    """The rules whose outputs ``rule`` reads, directly or not."""
    parents = {r: {p for p, children in graph.items() if r in children} for r in graph}
    found, todo = set(), list(parents[rule])
    while todo:
        r = todo.pop()
        if r not in found:
            found.add(r)
            todo += parents[r]
    return found


@pytest.fixture(scope="session")
def per_run_rules(rule_graph) -> set[str]:
    """The rules whose jobs state the run (its name, its config's hash): the summary,
    what is made of it, and the run folder; a renamed run makes them anew."""
    return {"summary", "run_folder"} | downstream(rule_graph, "summary")


@pytest.fixture(scope="session")
def simulations(tiny_checkout, rule_graph) -> set[str]:
    """The tiny run's rules that integrate a chain (:data:`SIMULATIONS`). Each of them
    runs :data:`SIMULATION_CODE`, and so does every rule that reads no other rule's
    outputs and integrates: a new or renamed one is listed here."""
    found = set(SIMULATIONS) & set(rule_graph)
    integrating = rules_running(tiny_checkout[0], *SIMULATION_CODE) & set(rule_graph)
    sources = {rule for rule in integrating if not upstream(rule_graph, rule)}
    assert "simulate" in found and sources <= found <= integrating, (found, integrating)
    return found


# ---- the run folder: contract files --------------------------------------------------


def test_contract_files_and_columns(tiny_checkout, rule_graph):
    work, out, _, _ = tiny_checkout
    for name, columns in TABLE_COLUMNS.items():
        table = pd.read_csv(out / "tables" / f"{name}.csv")
        missing = [c for c in columns if c not in table.columns]
        assert not missing, f"{name}.csv lacks {missing}"
        assert len(table) > 0, f"{name}.csv is empty"
        assert set(table["source"]) == {"simulation", "experiment"}
        assert set(table["model"]) == {"elastic", "viscoelastic", "virtual"}
    # The SSW tracked along the chain: simulated collisions only.
    track = pd.read_csv(out / "tables" / "ssw_track.csv")
    speed = pd.read_csv(out / "tables" / "ssw_speed.csv")
    for table, columns in ((track, TRACK_COLUMNS), (speed, SPEED_COLUMNS)):
        assert list(table.columns[: len(columns)]) == list(columns)
        assert set(table["source"]) == {"simulation"}
        assert set(table["model"]) == {"elastic", "viscoelastic"}
    for name, columns in RUN_TABLE_COLUMNS.items():
        table = pd.read_csv(out / "tables" / f"{name}.csv")
        assert not [c for c in columns if c not in table.columns], name
        assert table["headline" if name == "c_sensitivity" else "N"].notna().any(), name
    # Every figure rule of the run (a PDF and a PNG each) is in figures/, nothing else.
    drawn = {p.stem for p in (out / "figures").iterdir()}
    figure_rules = {rule for rule in rule_graph if is_figure_rule(work, rule)}
    assert drawn == figure_rules and drawn >= set(PAPER_FIGURES), (drawn, figure_rules)
    for name in drawn:
        assert (out / "figures" / f"{name}.pdf").read_bytes().startswith(b"%PDF"), name
        assert (out / "figures" / f"{name}.png").read_bytes().startswith(b"\x89PNG"), name
    for name in ("summary.json", "summary.md", "article.pdf", "experiment/selection.csv"):
        assert (out / name).is_file(), name
    assert (out / "logs").is_dir() and (out / "benchmarks").is_dir()


def is_figure_rule(work: Path, rule: str) -> bool:
    """Whether ``rule`` draws a figure: its outputs are a PDF and a PNG named after it."""
    for path in (work / "workflow" / "rules").glob("*.smk"):
        block = re.search(rf"^rule {rule}:\n(.*?)(?=^\S)", path.read_text() + "\n.", re.M | re.S)
        if block:
            return f"figures/{rule}.pdf" in block[1] and f"figures/{rule}.png" in block[1]
    return False


def test_virtual_experiment_and_selection(tiny_checkout):
    """The virtual experiment's datasets and trace files stay in the store; the run
    folder shows the selection, and the logs of the jobs that made them."""
    work, out, _, _ = tiny_checkout
    logs = [p.read_text() for p in (out / "logs").rglob("*.log")]
    for n in (16, 17):
        (raw,) = [p for p in store_of(work).glob(f"*-N{n}-*/raw") if p.is_dir()]
        assert "virtual experiment (model)" in (raw / "metadata.yaml").read_text()
        assert len(list(raw.glob("shot_*.csv"))) == 3 * (2 + 1)  # amplitudes x shots
        traces = pd.read_csv(stored_file(work, f"*/experiment/virtual_N{n}_traces.csv"))
        assert set(traces["source"]) == {"experiment"} and set(traces["N"]) == {n}
        assert any(f"N = {n}, sensors" in log and "collision" in log for log in logs), n
    assert any("virtual_N17_traces.csv: 6 collision and 3 reference shots" in log for log in logs)
    assert not (out / "experiment" / "raw").exists()  # intermediate: in the store only
    selection = pd.read_csv(out / "experiment" / "selection.csv")
    assert list(selection.columns) == [
        "source", "model", "N", "shot", "kind", "amplitude", "F_left_N", "F_right_N",
        "mismatch", "kept", "reason",
    ]  # fmt: skip
    assert len(selection) == 2 * 9 and selection["reason"].str.len().gt(0).all()
    rejected = selection[~selection["kept"]]
    kept = selection[selection["kept"] & (selection["kind"] == "collision")]
    assert (kept["mismatch"] <= 0.05).all() and (rejected["kind"] == "collision").all()
    # Rejected collisions are left out of the delays and the SSW.
    delays = pd.read_csv(out / "tables" / "delays.csv")
    experiment = delays[delays["source"] == "experiment"]
    assert not set(zip(rejected["N"], rejected["shot"])) & set(
        zip(experiment["N"], experiment["shot"])
    )
    assert set(zip(experiment["N"], experiment["shot"])) == set(zip(kept["N"], kept["shot"]))


def test_fits_cover_every_model_and_chain(tiny_checkout):
    _, out, _, _ = tiny_checkout
    fits = pd.read_csv(out / "tables" / "delay_fits.csv")
    keys = set(zip(fits["model"], fits["N"].astype(str), fits["estimator"]))
    for model in ("elastic", "viscoelastic"):
        for n in ("16", "17", "pooled"):
            for estimator in ("fit_full", "peak", "fit_rise"):
                assert (model, n, estimator) in keys
    for n in ("16", "17", "pooled"):
        assert ("virtual", n, "fit_full") in keys
    ok = fits[fits["estimator"] == "fit_full"]
    assert ok["C_us_N16"].between(20, 80).all(), ok
    ssw_fits = pd.read_csv(out / "tables" / "ssw_fits.csv")
    assert len(ssw_fits) == 4 + 2


def test_simulation_outputs_and_logs(tiny_checkout):
    """The simulations' traces and runs stay in the store; their logs are in the run
    folder's logs/ (logs/<rule>/<wildcards>.log)."""
    work, out, _, _ = tiny_checkout
    for model in ("elastic", "viscoelastic"):
        for n in (16, 17):
            traces = pd.read_csv(
                stored_file(work, f"*/simulation/{model}_N{n}_traces.csv"), nrows=5
            )
            assert list(traces.columns[:9]) == [
                "source", "model", "N", "shot", "kind", "amplitude",
                "v0_left_m_s", "v0_right_m_s", "t_s",
            ]  # fmt: skip
            runs = pd.read_csv(stored_file(work, f"*/simulation/{model}_N{n}_runs.csv"))
            assert len(runs) == 2 * 4  # collision + reference per speed
            assert (runs["energy_drift"] < 1e-6).all()
            log = (out / "logs" / "simulate" / f"{model}_N{n}.log").read_text()
            assert "energy drift" in log
    assert not (out / "simulation").exists()
    assert (out / "logs" / "summary.log").exists()
    assert (out / "benchmarks" / "simulate" / "elastic_N16.tsv").exists()


def test_summary(tiny_checkout):
    _, out, _, _ = tiny_checkout
    summary = json.loads((out / "summary.json").read_text())
    assert summary["run_name"] == "tiny"
    assert set(summary["constants"]) >= {
        "kappa_N_m1_5",
        "bead_mass_kg",
        "C_bal_paper_us_N16",
        "C_bal_exact_us_N16",
    }
    assert summary["paper"] == {
        "C_exp_us_N16": 45.9,
        "C_exp_err_us_N16": 0.5,
        "C_bal_us_N16": 49.74,
    }
    assert 0 < summary["max_energy_drift"] < 1e-8
    assert len(summary["delay_fits"]) == (2 + 1) * 3 * 3  # models + experiment, N x 3
    assert len(summary["ssw_fits"]) == 4 + 2
    assert summary["experiment_label"] == "virtual experiment (model)"
    selection = pd.read_csv(out / "experiment" / "selection.csv")
    counts = {(c["N"], c["kind"]): c for c in summary["selection"]}
    for n in (16, 17):
        chosen = selection[(selection["N"] == n) & (selection["kind"] == "collision")]
        assert counts[(n, "collision")]["kept"] == chosen["kept"].sum()
        assert counts[(n, "collision")]["rejected"] == (~chosen["kept"]).sum()
    assert set(summary["flagged"]) == {"pulses", "delays", "ssw"}
    assert summary["flagged"]["delays"]["experiment"]["rows"] > 0
    text = (out / "summary.md").read_text()
    assert "| quantity | paper | this run | note |" in text
    assert "| C_exp, experiment fit (µs N^1/6) | 45.9 ± 0.5 | virtual experiment (model): " in text
    assert "acceptance protocol, virtual experiment (model) |" in text
    assert "SSW slope, virtual experiment (model), N = 17" in text


def test_article_embeds_every_figure_and_prints_the_fits(tiny_checkout):
    """article.pdf (tests/test_article.py tests it closely on textless figures)."""
    import pypdf

    _, out, _, _ = tiny_checkout
    reader = pypdf.PdfReader(out / "article.pdf")
    forms = [
        xobject.get_object()["/Subtype"]
        for page in reader.pages
        for xobject in page.get("/Resources", {}).get("/XObject", {}).values()
    ]
    assert forms == ["/Form"] * len(list((out / "figures").glob("*.pdf")))
    text = re.sub(r"\s+", "", "".join(page.extract_text() for page in reader.pages))
    summary = json.loads((out / "summary.json").read_text())
    for row in summary["delay_fits"]:
        printed = plus_minus(row["C_us_N16"], row["C_stderr_us_N16"])
        assert re.sub(r"\s+", "", printed).replace("10^", "10") in text, row
    # Not a git checkout (a copy): the article says so rather than failing.
    assert "notagitcheckout" in text


def test_article_layout_is_clean(tiny_checkout):
    """No word off a page, in the bottom margin or overprinted (tests/pdf_layout.py), in
    the article the pipeline just built from real figures."""
    from pdf_layout import layout_problems

    _, out, _, _ = tiny_checkout
    assert layout_problems(out / "article.pdf") == []


def report_text(path: Path) -> str:
    """The text of Snakemake's HTML report: its markup (and the highlighted code's, kept
    as JSON strings in the page) removed, entities decoded."""
    text = re.sub(r"<[^<>]*>", "", path.read_text())
    return html.unescape(text.replace('\\"', '"').replace("\\n", "\n"))


def test_the_html_report_shows_every_figure_and_the_scripts_code(tiny_checkout, tmp_path):
    """``snakemake --report`` (the default install has what it needs): every figure the
    run folder shows is in the HTML under its own name, and so is the code of the rules'
    scripts, every line of workflow/scripts/simulate.py."""
    work, out, env, _ = tiny_checkout
    report = tmp_path / "report.html"
    succeeded(run(["--report", str(report), "--configfile", str(TINY)], work, env))
    page = report.read_text()
    figures = sorted(p.name for p in (out / "figures").glob("*.png"))
    assert len(figures) >= len(PAPER_FIGURES)
    assert not [name for name in figures if name not in page]
    text = report_text(report)
    lines = [line.strip() for line in (work / "workflow" / "scripts" / "simulate.py").open()]
    missing = [line for line in lines if line and line not in text]
    assert not missing, missing


def test_a_run_folder_is_plain_files_with_their_checksums(tiny_checkout, tmp_path):
    """The run folder holds files, no links, and SHA256SUMS lists every one of them as
    ``sha256sum -c`` checks it; a copy without the store beside it stays whole."""
    from chain.pipeline.provenance.checksums import checksum_problems

    _, out, _, _ = tiny_checkout
    assert not [p for p in out.rglob("*") if p.is_symlink()]
    listed = {line.split("  ", 1)[1] for line in (out / "SHA256SUMS").read_text().splitlines()}
    files = {
        str(p.relative_to(out))
        for p in out.rglob("*")
        if p.is_file() and not p.name.startswith(".") and p.name != "SHA256SUMS"
    }
    assert listed == files and len(files) > 50
    assert checksum_problems(out) == []
    moved = tmp_path / "archive" / "tiny"
    shutil.copytree(out, moved)  # no store beside it
    check = subprocess.run(
        ["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=moved, stdin=subprocess.DEVNULL
    )
    assert check.returncode == 0


def test_every_stored_result_is_sealed_with_what_it_read(tiny_checkout):
    """Each entry of the store lists its outputs and the stored inputs it read in its
    SHA256SUMS, as ``sha256sum -c`` checks them from the entry, and its outputs are
    read-only."""
    work, _, _, _ = tiny_checkout
    assert sealed_problems(work) == []
    reads = (entry_of(work, "delay_fits") / "SHA256SUMS").read_text()
    assert re.search(r"  \.\./pulses-[0-9a-f]{32}/tables/pulses\.csv$", reads, re.M), reads
    for name in entries(work):
        for line in (store_of(work) / name / "SHA256SUMS").read_text().splitlines():
            file = store_of(work) / name / line.split("  ", 1)[1]
            assert not file.stat().st_mode & 0o222, file


# ---- what Snakemake decides to run --------------------------------------------------------


def test_second_run_has_nothing_to_do(tiny_checkout):
    work, _, env, _ = tiny_checkout
    assert planned(work, env) == {}


def test_a_copied_checkout_has_nothing_to_do(tiny_checkout, tmp_path):
    """The store is named relative to the working directory, and a key holds no absolute
    path: a built run copied elsewhere (a CI cache, a colleague's copy) is up to date
    there."""
    copy, _, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    assert planned(copy, env) == {}


@pytest.mark.parametrize(
    "module",
    [
        "report/figures/fig4_delay_vs_force",
        "report/figures/style",
        "report/text/markdown",
        "analysis/selection",
        "physics/kernels",
    ],
)
def test_editing_the_library_reruns_what_depends_on_it(
    tiny_checkout, rule_graph, simulations, tmp_path, module
):
    """An edit of a library module changes the key of every job whose script runs it
    (read off the imports): exactly those jobs and the jobs after them run again."""
    work, out, env, library = checkout_copy(tiny_checkout[0], tmp_path)
    path = library / f"{module}.py"
    # An edit, not a touch: a key follows the content.
    path.write_bytes(path.read_bytes() + b"\n# an edit\n")
    running = rules_running(work, f"{module}.py") & set(rule_graph)
    assert running, f"no rule of the run runs {module}"
    jobs = planned(work, env)
    assert set(jobs) - {"all"} == running | downstream(rule_graph, *running), jobs
    if module.startswith("report/figures/fig"):
        # A figure is its module, its script and its rule: one figure job runs again.
        assert running == {module.rsplit("/", 1)[1]} and jobs[module.rsplit("/", 1)[1]] == 1
    if module == "physics/kernels":
        # Every simulation on our kernel: each job the tiny run made of them.
        assert {"simulate", "virtual_experiment"} <= running, running
        done = logged_jobs(out)
        assert {rule: jobs[rule] for rule in simulations & running} == {
            rule: done[rule] for rule in simulations & running
        }


def test_a_renamed_run_reuses_every_result(tiny_checkout, per_run_rules, tmp_path):
    """The same config under another run name computes only the jobs that state the
    run (its name, its config's hash): its results are the first run's bytes, and its
    logs of every other job are the stored jobs' own."""
    work, out, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    output = succeeded(run(tiny("--config", "run_name=again"), work, env))
    assert started(output) == per_run_rules
    again = work / "results" / "again"
    assert differing_results(out, again) == [] and same_summary(out, again)
    reused = [
        p.relative_to(out)
        for p in (out / "logs").rglob("*.log")
        if p.relative_to(out / "logs").parts[0].removesuffix(".log") not in per_run_rules
    ]
    assert len(reused) > 20
    assert [str(p) for p in reused if digest(out / p) != digest(again / p)] == []


@pytest.mark.heavy(cpu_s=20)
def test_a_what_ifs_dry_run_lists_the_jobs_it_then_runs(tiny_checkout, simulations, tmp_path):
    """An analysis what-if (its own run name, another main estimator): its dry run
    writes nothing and lists exactly the jobs (rule, inputs, outputs) that the run then
    starts, and no simulation among them; the pulses of every estimator are reused."""
    work, _, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    overlay = tmp_path / "peak.yaml"
    overlay.write_text("run_name: peak\nanalysis:\n  main_estimator: peak\n")
    args = tiny(str(overlay))
    before = listing(work / "results")
    dry = succeeded(run(["-n", *args], work, env))
    assert listing(work / "results") == before  # a dry run writes nothing
    output = succeeded(run(args, work, env))
    assert jobs(output) == jobs(dry) and len(jobs(dry)) > 10
    rules = started(output)
    assert not rules & simulations, f"an analysis what-if simulates again: {rules & simulations}"
    assert "pulses" not in rules
    assert {"delay_fits", "ssw", "summary", "article", "run_folder"} <= rules, rules


@pytest.mark.heavy(cpu_s=6)
def test_forcing_a_rule_reruns_it_and_exactly_what_follows(
    tiny_checkout, rule_graph, simulations, tmp_path
):
    """``-R delay_fits`` reruns delay_fits and every job after it (figures, summary,
    article, run folder), nothing else, to the same bytes; under a new run name it
    would start the same jobs, no simulation among them."""
    work, out, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    expected = {"delay_fits"} | downstream(rule_graph, "delay_fits")
    assert {"summary", "article", "run_folder"} <= expected, expected
    output = succeeded(run(tiny("-R", "delay_fits"), work, env))
    assert started(output) == expected
    assert differing_results(tiny_checkout[1], out, per_run=True) == []
    # Under a new run name (a dry run: it lists what the run starts, the what-if test
    # shows), the same jobs.
    output = succeeded(
        run(["-n", *tiny("-R", "delay_fits", "--config", "run_name=again")], work, env)
    )
    assert started(output) == expected and not started(output) & simulations


@pytest.mark.heavy(cpu_s=5)
def test_until_and_omit_from_stop_where_snakemake_says(tiny_checkout, rule_graph, tmp_path):
    """A what-if that changes how the experiment's datasets are loaded (new run name),
    run ``--omit-from pulses``: the loading runs, nothing from pulses on; then
    ``--until pulses``: pulses runs and nothing after it. Neither writes the run folder
    or a figure."""
    work, _, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    overlay = tmp_path / "skip.yaml"
    overlay.write_text("run_name: partial\nexperiment:\n  bad_channels: skip\n")
    before = entries(work)
    after_pulses = {"pulses"} | downstream(rule_graph, "pulses")
    output = succeeded(run(tiny(str(overlay), "--omit-from", "pulses"), work, env))
    assert started(output) and not started(output) & after_pulses, started(output)
    output = succeeded(run(tiny(str(overlay), "--until", "pulses"), work, env))
    up_to_pulses = {"pulses"} | upstream(rule_graph, "pulses")
    assert "pulses" in started(output) and started(output) <= up_to_pulses, started(output)
    new = {rule for name, rule in entries(work).items() if name not in before}
    assert "pulses" in new and new <= up_to_pulses, new
    assert not (work / "results" / "partial").exists()


@pytest.mark.heavy(cpu_s=45)
def test_forceall_recomputes_every_job_to_the_stored_bytes(tiny_checkout, tmp_path):
    """``--forceall``: its dry run writes nothing under results/ (the store included)
    and lists every job of the run; the run, on 1 core under another string-hash seed,
    starts exactly those, seals every entry of the store anew with the digests it had,
    and gives the run folder's bytes again, summary.md and the article included (the
    tiny run was built on 2 cores: test_reproducibility.py relies on this)."""
    work, out, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    store = store_of(work)
    before = listing(work / "results")
    sums = {name: (store / name / "SHA256SUMS").read_bytes() for name in entries(work)}
    sealed = {name: (store / name / "SHA256SUMS").stat().st_mtime_ns for name in sums}
    dry = succeeded(run(["-n", "--forceall", *tiny()], work, env))
    assert listing(work / "results") == before
    planned_rules = Counter(rule for (rule, _, _), n in jobs(dry).items() for _ in range(n))
    assert planned_rules == logged_jobs(out) + Counter(["run_folder", "all"])
    args = ["--forceall", "--cores", "1", "--configfile", str(TINY)]
    output = succeeded(run(args, work, {**env, "PYTHONHASHSEED": "2"}))
    assert jobs(output) == jobs(dry)
    assert {name: (store / name / "SHA256SUMS").read_bytes() for name in entries(work)} == sums
    assert not [n for n in sums if (store / n / "SHA256SUMS").stat().st_mtime_ns == sealed[n]]
    assert differing_results(tiny_checkout[1], out, per_run=True) == []


@pytest.mark.heavy(cpu_s=10)
def test_rerun_triggers_mtime_after_a_stored_file_is_touched(tiny_checkout, rule_graph, tmp_path):
    """A stored table touched (newer than everything made from it, its bytes the stored
    ones): not damage, and Snakemake (9.27.1) starts nothing, since the checksum it
    recorded of the input is unchanged. Made to judge by the time alone
    (``--rerun-triggers mtime --max-checksum-file-size 0``), it reruns every job after
    the table, as it documents for a newer input, and its dry run lists exactly those,
    writing nothing. Afterwards every entry of the store verifies with its own
    SHA256SUMS (no result computed from bytes that are no longer there), a dry run has
    nothing to do (the keys are the recipes'), and the run folder has the same bytes."""
    work, out, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    entry = entry_of(work, "delay_fits")
    table = entry / "tables" / "delay_fits.csv"
    newest = max(p.stat().st_mtime_ns for p in (work / "results").rglob("*") if p.is_file())
    os.utime(table, ns=(newest + 10**9,) * 2)  # touched, a second after all, whatever the clock
    assert planned(work, env) == {}
    args = tiny("--rerun-triggers", "mtime", "--max-checksum-file-size", "0")
    before = listing(work / "results")
    dry = succeeded(run(["-n", *args], work, env))
    assert listing(work / "results") == before and "damaged" not in dry
    output = succeeded(run(args, work, env))
    assert jobs(output) == jobs(dry)
    assert started(output) == downstream(rule_graph, "delay_fits"), output[-3000:]
    assert "damaged" not in output and entry.is_dir()
    assert sealed_problems(work) == []
    assert planned(work, env) == {}
    assert differing_results(tiny_checkout[1], out, per_run=True) == []


@pytest.mark.heavy(cpu_s=8)
def test_a_damaged_stored_result_is_named_and_computed_anew(tiny_checkout, tmp_path):
    """A stored table rewritten behind the store's back, its time and mode restored (the
    look over the store before any job cannot see it): the first job that reads it
    names the file on the console, discards its entry and fails; the next run computes
    it anew, to the bytes the tiny run gave."""
    work, out, env, _ = checkout_copy(tiny_checkout[0], tmp_path)
    table = entry_of(work, "delay_fits") / "tables" / "delay_fits.csv"
    info = table.stat()
    os.chmod(table, 0o600)
    table.write_bytes(table.read_bytes().replace(b"1", b"2", 1))
    os.chmod(table, info.st_mode)
    os.utime(table, ns=(info.st_atime_ns, info.st_mtime_ns))
    args = tiny("--config", "run_name=again")
    failed = run(args, work, env)
    output = failed.stdout + failed.stderr
    assert failed.returncode != 0, output[-3000:]
    assert f"stored result {table} does not match its digest" in output, output[-5000:]
    assert not table.parent.parent.exists()  # the entry is discarded
    output = succeeded(run(args, work, env))
    assert "delay_fits" in started(output)
    again = work / "results" / "again"
    assert differing_results(out, again) == [] and same_summary(out, again)


# ---- a measured dataset --------------------------------------------------------------


@pytest.fixture(scope="session")
def measured(built_once):
    """The tiny run on the committed dataset, read as a lab's measured dataset (done once
    per test session): (work directory, run folder)."""

    def build(work: Path) -> None:
        shutil.copy(ROOT / "config.yaml", work / "config.yaml")
        shutil.copytree(ROOT / DATASET, work / DATASET)
        env = {k: v for k, v in os.environ.items() if not k.startswith("HERTZCHAIN_STORE")}
        args = ["--cores", "2", "--configfile", str(TINY_MEASURED)]
        succeeded(run(args, work, env))

    work = built_once("measured", build)
    return work, work / "results" / "tiny_measured"


def test_measured_dataset_runs_the_same_analysis(measured):
    work, out = measured
    assert not [rule for rule in entries(work).values() if rule == "virtual_experiment"]
    traces = pd.read_csv(stored_file(work, "*/experiment/virtual_small_N25_traces.csv"))
    assert set(traces["model"]) == {"virtual_small"} and traces["shot"].nunique() == 6
    selection = pd.read_csv(out / "experiment" / "selection.csv")
    assert len(selection) == 6 and set(selection["model"]) == {"virtual_small"}
    for name, columns in TABLE_COLUMNS.items():
        table = pd.read_csv(out / "tables" / f"{name}.csv")
        assert not [c for c in columns if c not in table.columns], name
        assert set(table["source"]) == {"simulation", "experiment"}, name
    fits = pd.read_csv(out / "tables" / "delay_fits.csv")
    pooled = fits[
        (fits["source"] == "experiment")
        & (fits["N"] == "pooled")
        & (fits["estimator"] == "fit_full")
    ]
    assert pooled["C_us_N16"].between(20, 80).all() and (pooled["n_points"] >= 4).all()
    assert (out / "figures" / "fig2_experiment_traces.png").read_bytes().startswith(b"\x89PNG")
    summary = json.loads((out / "summary.json").read_text())
    # Written by the virtual experiment: labelled as a model even when read as "measured".
    assert summary["experiment_label"] == "virtual experiment (model): virtual_small"
    assert {(c["kind"], c["kept"] + c["rejected"]) for c in summary["selection"]} == {
        ("collision", 4),
        ("reference", 2),
    }
    check = subprocess.run(
        ["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=out, stdin=subprocess.DEVNULL
    )
    assert check.returncode == 0


# ---- the workflow's files --------------------------------------------------------------


def test_lint_clean(tmp_path):
    """``snakemake --lint`` (in a folder of its own: it is no dry run, and makes the
    store's folder)."""
    args = ["--lint", "--configfile", str(ROOT / "config.yaml")]
    output = run(args, tmp_path, {**os.environ}, timeout=300)
    text = output.stdout + output.stderr
    assert "Congratulations, your workflow is in a good condition!" in text, text[-3000:]


def test_snakefmt_clean():
    snakefmt = shutil.which("snakefmt")
    if snakefmt is None:
        pytest.skip("snakefmt is not installed")
    result = subprocess.run(
        [snakefmt, "--check", "Snakefile", "workflow"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        stdin=subprocess.DEVNULL,
    )
    assert result.returncode == 0, result.stdout + result.stderr
