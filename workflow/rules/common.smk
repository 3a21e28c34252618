# Shared definitions: the config check, the run plan, output paths, the library files
# each stage depends on, and the input functions of more than one rule file. Every fact
# of the config (speeds, chains, jobs, studies, targets) comes from the plan
# (chain.pipeline.plan.run_plan.RunPlan); each stage's helpers sit in its own rule file.

import importlib.util
import os
from pathlib import Path

from snakemake import __version__ as SNAKEMAKE_VERSION
from snakemake.exceptions import WorkflowError
from snakemake.scheduling.job_scheduler import JobScheduler

from chain.pipeline.config.check import check_config
from chain.pipeline.plan.datasets import (
    DEFAULT_CACHE as DATASET_CHECK_CACHE,
    check_experiment_datasets,
)
from chain.pipeline.plan.code import remember_imports, save_imports, script_sources
from chain.pipeline.plan.run_plan import RunPlan
from chain.pipeline.provenance.record import run_provenance
from chain.pipeline.run.reuse import Job, older_results, run_ended, run_started
from chain.pipeline.run.snakemake_patches import patch_snakemake
from chain.pipeline.run.store import Store, StoreError

check_config(config)
PLAN = RunPlan(config)

# The result store (chain.pipeline.run.reuse): no one else may write it, checked here.
try:
    STORE = Store.open(os.environ) if config["reuse"] else None
    for line in older_results(PLAN.out) if workflow.is_main_process else []:
        print(line)
except StoreError as error:
    raise WorkflowError(str(error)) from None
# Two defects of Snakemake's scheduler, patched (chain.pipeline.run.snakemake_patches); the
# console says so when this Snakemake is not the release they were written for.
for line in patch_snakemake(JobScheduler, SNAKEMAKE_VERSION):
    if workflow.is_main_process:
        print(line)
# Commit, config hash and installed versions (summary.json and the article), read once.
PROVENANCE = run_provenance(config, workflow.basedir)


wildcard_constraints:
    source="simulation|experiment",
    model="[A-Za-z][A-Za-z0-9-]*",
    N=r"\d+",


RUN = PLAN.run_name
OUT = PLAN.out
FIGURES = PLAN.figures
TABLES = PLAN.tables
LOGS = f"{OUT}/logs"
ENV = "../envs/hertzchain.yaml"
BENCH = f"{OUT}/benchmarks"

# The code each job runs is an input of its rule: its script, the script's local
# helpers and every chain module it imports (chain.pipeline.plan.code), so editing the
# physics reruns the simulations, and one figure's module redraws that figure only.
# Paths relative to the working directory: a moved or copied checkout has nothing to
# do. PACKAGE_DIR is the package the jobs import (src/chain, or PYTHONPATH's copy). The
# import statements are remembered by file version between commands.
PACKAGE_DIR = Path(importlib.util.find_spec("chain").origin).parent
IMPORTS_STORE = DATASET_CHECK_CACHE.parent / "imports.json"
remember_imports(IMPORTS_STORE)


def code(script):
    """workflow/scripts/<script>.py and the source files it runs."""
    path = Path(workflow.basedir, "workflow", "scripts", f"{script}.py")
    return [os.path.relpath(path), *script_sources(path, PACKAGE_DIR)]


# A "part" is one trace file: (source, model, N). The experiment's: one per chain of
# PLAN.experiment (virtual: experiment/raw/N<N>/ from the virtual_experiment rule;
# measured: a dataset folder); the simulation's: analyse.smk.
EXPERIMENT_PARTS = [("experiment", part.name, part.n_beads) for part in PLAN.experiment]
# Every shot file of every measured dataset, now: all problems on the console at once,
# before any job (verdicts cached by file content in DATASET_CHECK_CACHE).
check_experiment_datasets(config, list(PLAN.experiment))
# The 5 % amplitude match of the experiment's collisions (rule selection).
SELECTION = [f"{OUT}/experiment/selection.csv"] if EXPERIMENT_PARTS else []


def trace_file(source, model, n):
    return f"{OUT}/{source}/{model}_N{n}_traces.csv"


def selection_files(wildcards):
    return list(SELECTION)


def experiment_label(wildcards):
    return PLAN.experiment_label


def figure(name):
    """The PDF and PNG of a figure (contract name without extension)."""
    return [f"{FIGURES}/{name}.pdf", f"{FIGURES}/{name}.png"]


def figure_outputs(name):
    pdf, png = figure(name)
    caption = f"../report/{name}.rst"
    return {"pdf": pdf, "png": report(png, caption=caption, category="Figures")}


def final_targets(wildcards=None):
    return PLAN.targets()


def dag_jobs():
    """The script jobs this run executes, read off Snakemake's DAG (the forecast)."""
    jobs = [j for j in workflow.dag.needrun_jobs() if j.rule.script]
    return [Job.of(j.rule.name, j.wildcards, j.params, j.input, j.output) for j in jobs]


onstart:
    # -F, -R, --forcerun: what Snakemake reruns, it computes (not from the store).
    flags = workflow.dag_settings
    forced = flags.forceall or bool(flags.forcerun) or flags.forcetargets
    run_started(dag_jobs(), STORE, OUT, config["reuse"], forced)


onsuccess:
    run_ended(OUT)


onerror:
    run_ended(OUT)
