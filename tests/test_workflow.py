"""The Snakemake pipeline end to end on a tiny config (tests/configs/tiny.yaml) in a
temporary directory: every contract file appears with its columns, the virtual
experiment runs through the acceptance protocol into Fig. 2 and the tables, a second run
has nothing to do, editing a library file reruns exactly what depends on it, and the
workflow is lint- and format-clean. A second tiny run (tests/configs/tiny_measured.yaml)
reads the committed dataset tests/data/virtual_small as a lab's measured dataset.

The run uses a copy of the library (``PYTHONPATH``) so that the test can touch its
source files without touching the checkout's.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from chain.analysis.ssw_speed import SPEED_COLUMNS
from chain.analysis.ssw_track import TRACK_COLUMNS
from chain.pipeline.plan import figures
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

#: Rules that integrate a chain (or run LAMMPS): an analysis what-if starts none.
SIMULATIONS = (
    "simulate", "virtual_experiment", "ssw_track", "ssw_fields", "lammps_setting",
    "lammps_check", "ablation_variant", "c_sensitivity",
)  # fmt: skip

FIGURES = [
    "fig1_setup",
    "fig2_experiment_traces",
    "fig3_simulation_traces",
    "fig4_delay_vs_force",
    "fig5_ssw_vs_force",
    "fig_parity_ssw_vs_N",
    "ssw_spacetime",
    "fig_c_sensitivity",
    "fig_ssw_mechanisms",
]


def env() -> dict:
    return dict(os.environ)


#: Longest a Snakemake call may take, s: a guard against a hang, far above a tiny run's
#: minutes on a machine shared with other workers (pytest-xdist) or other work.
TIMEOUT = 1800


def run(args, work: Path, env: dict, timeout=TIMEOUT) -> subprocess.CompletedProcess:
    """Snakemake in ``work``, with the work tree's own Snakefile if it has one (a copied
    checkout), else the repository's; started in ``work``, as a user would, so that the
    workflow profile is the work tree's (profiles/default), wherever pytest started."""
    snakefile = work / "Snakefile" if (work / "Snakefile").exists() else ROOT / "Snakefile"
    return subprocess.run(
        [*SNAKEMAKE, "--snakefile", str(snakefile), "--directory", str(work), *args],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )


def planned_jobs(work: Path, env: dict) -> dict[str, int]:
    """Rule -> number of jobs a dry run would execute."""
    result = run(["-n", "--cores", "2", "--configfile", str(TINY)], work, env)
    assert result.returncode == 0, result.stderr[-3000:]
    text = result.stdout + result.stderr
    if "Nothing to be done" in text:
        return {}
    table = text.split("Job stats:", 1)[1].split("total", 1)[0]
    return {m[1]: int(m[2]) for m in re.finditer(r"^(\w+)\s+(\d+)\s*$", table, re.M)}


@pytest.fixture(scope="session")
def tiny(tiny_run):
    """The tiny run (conftest.py's ``tiny_run``: built once per test session with 2 cores
    in a copy of the checkout: Snakefile, workflow, config, library): (work directory,
    results directory, env, library folder). Shared by every test that asks for it, and
    by test_reproducibility.py: a test that edits the copy edits a copy of it
    (:func:`checkout_copy`)."""
    return checkout(tiny_run)


def checkout(work: Path) -> tuple[Path, Path, dict, Path]:
    """(work directory, results directory, env, library folder) of a tiny run's checkout:
    its jobs import the library copied into it (``src/chain``)."""
    env = {**os.environ, "PYTHONPATH": str(work / "src")}
    return work, work / "results" / "tiny", env, work / "src" / "chain"


def checkout_copy(work: Path, folder: Path) -> tuple[Path, Path, dict, Path]:
    """A copy of the tiny run's checkout in ``folder``, results and Snakemake's records
    included (copy2 keeps the times that tell Snakemake what is up to date)."""
    copy = folder / "elsewhere" / "checkout"
    shutil.copytree(work, copy, symlinks=True, copy_function=shutil.copy2)
    return checkout(copy)


def test_contract_files_and_columns(tiny):
    _, out, _, _ = tiny
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
    for name in FIGURES:
        assert (out / "figures" / f"{name}.pdf").read_bytes().startswith(b"%PDF"), name
        assert (out / "figures" / f"{name}.png").read_bytes().startswith(b"\x89PNG"), name


def test_virtual_experiment_and_selection(tiny):
    _, out, _, _ = tiny
    for n in (16, 17):
        raw = out / "experiment" / "raw" / f"N{n}"
        metadata = (raw / "metadata.yaml").read_text()
        assert "virtual experiment (model)" in metadata
        assert len(list(raw.glob("shot_*.csv"))) == 3 * (2 + 1)  # amplitudes x shots
        traces = pd.read_csv(out / "experiment" / f"virtual_N{n}_traces.csv")
        assert set(traces["source"]) == {"experiment"} and set(traces["N"]) == {n}
        assert (out / "logs" / "experiment" / f"virtual_N{n}.log").exists()
    assert (
        "virtual_N17_traces.csv: 6 collision and 3 reference shots"
        in (out / "logs" / "experiment" / "traces.log").read_text()
    )
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


def test_fits_cover_every_model_and_chain(tiny):
    _, out, _, _ = tiny
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


def test_simulation_outputs_and_logs(tiny):
    _, out, _, _ = tiny
    for model in ("elastic", "viscoelastic"):
        for n in (16, 17):
            traces = pd.read_csv(out / "simulation" / f"{model}_N{n}_traces.csv", nrows=5)
            assert list(traces.columns[:9]) == [
                "source", "model", "N", "shot", "kind", "amplitude",
                "v0_left_m_s", "v0_right_m_s", "t_s",
            ]  # fmt: skip
            runs = pd.read_csv(out / "simulation" / f"{model}_N{n}_runs.csv")
            assert len(runs) == 2 * 4  # collision + reference per speed
            assert (runs["energy_drift"] < 1e-6).all()
            log = (out / "logs" / "simulate" / f"{model}_N{n}.log").read_text()
            assert "energy drift" in log
    assert (out / "logs" / "summary.log").exists()


def test_summary(tiny):
    _, out, _, _ = tiny
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


def test_article_embeds_every_figure_and_prints_the_fits(tiny):
    """article.pdf (tests/test_article.py tests it closely on textless figures)."""
    import pypdf

    _, out, _, _ = tiny
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


def test_every_registered_figure_is_in_the_html_report(tiny, tmp_path):
    """Each figure of the registry the tiny run made is in Snakemake's HTML report
    (``--report``), under its own name, and the run made no figure the registry lacks."""
    work, out, env, _ = tiny
    made = {path.stem for path in (out / "figures").glob("*.png")}
    assert made <= {figure.name for figure in figures.FIGURES} and made >= set(FIGURES)
    report = tmp_path / "report.html"
    result = run(["--report", str(report), "--configfile", str(TINY)], work, env)
    assert result.returncode == 0, result.stderr[-3000:]
    html = report.read_text()
    assert not [name for name in sorted(made) if f"{name}.png" not in html]


def test_article_layout_is_clean(tiny):
    """No word off a page, in the bottom margin or overprinted (tests/pdf_layout.py), in
    the article the pipeline just built from real figures."""
    from pdf_layout import layout_problems

    _, out, _, _ = tiny
    assert layout_problems(out / "article.pdf") == []


def test_second_run_has_nothing_to_do(tiny):
    work, _, env, _ = tiny
    assert planned_jobs(work, env) == {}


@pytest.mark.parametrize(
    ("module", "expected", "untouched"),
    [
        # None: exactly the expected jobs, nothing else (the article embeds every figure).
        ("report/figures/style", set(FIGURES) | {"article", "all"}, None),
        ("report/figures/fig4_delay_vs_force", {"fig4_delay_vs_force", "article", "all"}, None),
        ("report/figures/trace_panels",
         {"fig2_experiment_traces", "fig3_simulation_traces", "article", "all"}, None),
        ("report/text/markdown", {"summary_md", "all"}, None),
        ("analysis/ssw", {"ssw", "ssw_fits", "fig2_experiment_traces", "fig3_simulation_traces",
                          "fig5_ssw_vs_force", "summary"},
         {"simulate", "virtual_experiment", "experiment_traces", "pulses", "selection",
          "delays"}),
        ("analysis/selection", {"selection", "delays", "ssw", "fig2_experiment_traces",
                                "summary"},
         {"simulate", "virtual_experiment", "experiment_traces", "pulses"}),
        ("apparatus/virtual", {"virtual_experiment", "experiment_traces", "pulses",
                               "selection"},
         {"simulate", "fig1_setup"}),
        ("physics/model", {"simulate", "virtual_experiment", "pulses", "delays", "ssw",
                           "summary"},
         set()),
    ],
)  # fmt: skip
def test_editing_the_library_reruns_what_depends_on_it(tiny, tmp_path, module, expected, untouched):
    # In a copy of the built checkout: the tiny run itself is shared with other tests.
    work, _, env, library = checkout_copy(tiny[0], tmp_path)
    path = library / f"{module}.py"
    # An edit, not a touch: Snakemake reruns only when the content changed.
    path.write_bytes(path.read_bytes() + b"\n# an edit\n")
    jobs = planned_jobs(work, env)
    if untouched is None:
        assert set(jobs) == expected, jobs
    else:
        assert expected <= set(jobs), jobs
        assert not untouched & set(jobs), jobs
    if module == "physics/model":
        assert jobs["simulate"] == 4 and jobs["virtual_experiment"] == 2
    if module == "apparatus/virtual":
        assert jobs["virtual_experiment"] == 2


def test_a_copied_checkout_has_nothing_to_do(tiny, tmp_path):
    """The rules name the library by paths relative to the working directory, so a
    built run copied elsewhere (a CI cache, a colleague's copy) is up to date there."""
    copy, _, env, _ = checkout_copy(tiny[0], tmp_path)
    assert planned_jobs(copy, env) == {}


# ---- reuse across runs (chain.pipeline.run.reuse, chain.pipeline.run.store) -------------

#: What a run states about itself (its name, provenance): made anew by every run.
PER_RUN_LOGS = {"summary.log", "summary_md.log", "article.log"}
#: Files a run writes about itself or its times (and logs/, benchmarks/); every other
#: file is a result.
PER_RUN_FILES = ("summary.json", "summary.md", "article.pdf", ".snakemake_timestamp", "SHA256SUMS")


def ran(out: Path) -> set[str]:
    """Logs (relative to logs/) of the jobs that computed: a job that took its result
    from the store says so in its log, and nothing else."""
    logs = out / "logs"
    return {
        str(p.relative_to(logs))
        for p in logs.rglob("*.log")
        if not p.read_text().startswith("taken from the store: ")
    }


def started(output: str) -> set[str]:
    """The rules of the jobs Snakemake started (or, dry, would start): its output's
    ``rule <name>:`` lines."""
    return set(re.findall(r"^(?:local)?rule (\w+):$", output, re.M)) - {"all"}


def differing_results(a: Path, b: Path, *, per_run: bool = False) -> list[str]:
    """Result files of run folder ``a`` missing from ``b`` or with other bytes there; with
    ``per_run``, the files a run writes about itself too (summary, article), all but
    SHA256SUMS (it lists the logs)."""
    skipped = {"SHA256SUMS"} if per_run else set(PER_RUN_FILES)
    names = [
        p.relative_to(a)
        for p in sorted(a.rglob("*"))
        if p.is_file()
        and not {"logs", "benchmarks"} & set(p.relative_to(a).parts)
        and p.name not in skipped
    ]
    assert len(names) > 50, names  # tables, figures, traces, the virtual datasets
    return [
        str(n)
        for n in names
        if not (b / n).is_file() or (a / n).read_bytes() != (b / n).read_bytes()
    ]


def same_summary(a: Path, b: Path) -> bool:
    """summary.json of two runs equal but for the run's name and provenance."""
    first, second = (json.loads((folder / "summary.json").read_text()) for folder in (a, b))
    for summary in (first, second):
        summary.pop("run_name"), summary.pop("provenance")
    return first == second


def test_a_renamed_run_reuses_every_result(tiny, tmp_path):
    """The same config under another run name starts no job but those stating the run
    (Snakemake never sees the others: the store filled the run folder before it looked),
    and its results are the first run's bytes."""
    work, out, env, _ = checkout_copy(tiny[0], tmp_path)
    result = run(
        ["--cores", "2", "--configfile", str(TINY), "--config", "run_name=again"], work, env
    )
    assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]
    again = work / "results" / "again"
    assert ran(again) == PER_RUN_LOGS
    assert differing_results(out, again) == [] and same_summary(out, again)
    assert started(result.stdout + result.stderr) == {"summary", "summary_md", "article"}
    # The line before the first job, and the tally at the end, agree with what ran.
    forecast = re.search(r"(\d+) of (\d+) jobs take a stored result, (\d+) compute", result.stdout)
    assert forecast, result.stdout[-3000:]
    reused, jobs, computed = map(int, forecast.groups())
    assert computed == len(PER_RUN_LOGS) and reused + computed == jobs > 30
    tally = f"hertzchain store: {reused} results taken, {computed} computed and stored"
    assert tally in result.stdout + result.stderr


@pytest.mark.heavy(cpu_s=25)
def test_an_analysis_what_if_runs_no_simulation(tiny, tmp_path):
    """A what-if changing only an analysis key reuses every simulation, the virtual
    experiment, the tracks and the studies' simulations (their jobs fit every
    estimator); the analysis the key changes runs again, and so do the tables that take
    the main estimator's rows of the studies."""
    work, _, env, _ = checkout_copy(tiny[0], tmp_path)
    overlay = tmp_path / "peak.yaml"
    overlay.write_text("run_name: peak\nanalysis:\n  main_estimator: peak\n")
    args = ["--cores", "2", "--configfile", str(TINY), str(overlay)]
    dry = run(["-n", *args], work, env)
    assert dry.returncode == 0, (dry.stdout + dry.stderr)[-5000:]
    assert not (work / "results" / "peak").exists()  # a dry run writes nothing
    result = run(args, work, env)
    assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]
    # Snakemake starts (and its dry run lists) exactly the jobs that compute, and no
    # simulation among them.
    rules = started(result.stdout + result.stderr)
    assert rules == started(dry.stdout + dry.stderr)
    assert not rules & set(SIMULATIONS), rules
    jobs = ran(work / "results" / "peak")
    simulations = {
        j
        for j in jobs
        if j.startswith(("simulate/", "lammps/", "experiment/virtual", "ablation/", "c_sens"))
    }
    assert simulations == set(), jobs
    assert {"tables/ssw.log", "experiment/selection.log"} <= jobs, jobs
    studies = {"tables/ablation_exponent.log", "tables/c_sensitivity.log"}
    assert studies | {"tables/ssw_mechanisms.log"} <= jobs, jobs
    assert "tables/pulses.log" not in jobs  # every estimator's pulses are computed anyway


@pytest.mark.heavy(cpu_s=85)
def test_a_recomputed_run_gives_the_stored_bytes(tiny, tmp_path):
    """``--forceall`` recomputes every job of the tiny run (Snakemake's convention)
    under another string-hash seed: every result has the bytes that were stored, so the
    store keeps its entries and names no difference. One run shows that a reused result
    is the recomputed one and that a second build gives the same bytes.

    It runs on 1 core (the tiny run on 2): the same bytes in every file of
    ``results/tiny/`` but ``logs/``, ``benchmarks/`` and SHA256SUMS, summary.md and the
    article included, show that 1 core gives those of 2 (test_reproducibility.py)."""
    work, out, env, _ = checkout_copy(tiny[0], tmp_path)
    store = work / "results" / ".store"
    stored = sorted(p.name for p in store.glob("??/*"))
    args = ["--forceall", "--cores", "1", "--configfile", str(TINY)]
    result = run(args, work, {**env, "PYTHONHASHSEED": "2"})
    output = result.stdout + result.stderr
    assert result.returncode == 0, output[-5000:]
    assert "hertzchain store: forced, results replace: the run's " in output
    assert "hertzchain store: 0 results taken" in output and "differ" not in output
    assert ran(out) == {str(p.relative_to(out / "logs")) for p in (out / "logs").rglob("*.log")}
    assert sorted(p.name for p in store.glob("??/*")) == stored
    assert differing_results(tiny[1], out) == [] and same_summary(tiny[1], out)
    assert differing_results(tiny[1], out, per_run=True) == []


def test_a_run_folder_is_plain_files_with_their_checksums(tiny, tmp_path):
    """The run folder holds files, no links, and SHA256SUMS lists every one of them as
    ``sha256sum -c`` checks it; a copy, a move of the checkout or an emptied store
    leaves it whole."""
    _, out, _, _ = tiny
    assert not [p for p in out.rglob("*") if p.is_symlink()]
    sums = (out / "SHA256SUMS").read_text().splitlines()
    listed = {line.split("  ", 1)[1] for line in sums}
    files = {
        str(p.relative_to(out))
        for p in out.rglob("*")
        if p.is_file() and not p.name.startswith(".") and p.name != "SHA256SUMS"
    }
    assert listed == files and len(files) > 50
    moved = tmp_path / "archive" / "tiny"
    shutil.copytree(out, moved)  # no store beside it
    check = subprocess.run(["sha256sum", "-c", "--quiet", "SHA256SUMS"], cwd=moved)
    assert check.returncode == 0


@pytest.mark.heavy(cpu_s=20)
def test_a_damaged_stored_result_is_named_and_computed_anew(tiny, tmp_path):
    """A stored simulation trace rewritten behind the store's back (another user of a
    world-writable store did so to Snakemake's cache): the next run names it on the
    console, computes it anew and gives the bytes the tiny run gave."""
    work, out, env, _ = checkout_copy(tiny[0], tmp_path)
    store = work / "results" / ".store"
    trace = "simulation/elastic_N16_traces.csv"
    (stored,) = [
        manifest.parent / "files" / str(record["paths"].index(trace))
        for manifest in store.glob("??/*/manifest.json")
        if trace in (record := json.loads(manifest.read_text()))["paths"]
    ]
    os.chmod(stored, 0o600)
    stored.write_bytes(stored.read_bytes().replace(b"1", b"2", 1))
    args = ["--cores", "2", "--configfile", str(TINY), "--config", "run_name=again"]
    result = run(args, work, env)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output[-5000:]
    assert "simulate (model=elastic, N=16)" in output and "failed its check" in output
    again = work / "results" / "again"
    assert "simulate/elastic_N16.log" in ran(again)
    assert differing_results(out, again) == []


@pytest.fixture(scope="session")
def measured(built_once):
    """The tiny run on the committed dataset, read as a lab's measured dataset (done once
    per test session)."""

    def build(work: Path) -> None:
        shutil.copy(ROOT / "config.yaml", work / "config.yaml")
        shutil.copytree(ROOT / DATASET, work / DATASET)
        # The experiment's part of the pipeline: tables, Fig. 2 and the summary (Fig. 1,
        # 3-5 are the tiny run's business); relative to the working directory, as
        # Snakemake names its outputs.
        targets = [
            "results/tiny_measured/summary.json",
            "results/tiny_measured/figures/fig2_experiment_traces.png",
        ]
        result = run([*targets, "--cores", "2", "--configfile", str(TINY_MEASURED)], work, env())
        assert result.returncode == 0, (result.stdout + result.stderr)[-5000:]

    return built_once("measured", build) / "results" / "tiny_measured"


def test_measured_dataset_runs_the_same_analysis(measured):
    out = measured
    assert not (out / "experiment" / "raw").exists(), "no virtual experiment for measured data"
    traces = pd.read_csv(out / "experiment" / "virtual_small_N25_traces.csv")
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


def test_lint_clean():
    result = subprocess.run(
        [*SNAKEMAKE, "--lint"], cwd=ROOT, capture_output=True, text=True, timeout=300
    )
    output = result.stdout + result.stderr
    assert "Congratulations, your workflow is in a good condition!" in output, output[-3000:]


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
    )
    assert result.returncode == 0, result.stdout + result.stderr
