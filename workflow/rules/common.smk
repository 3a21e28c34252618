# Shared definitions: the config check, the run plan, the code each job runs, the store
# and its part in the run. Every fact of the config (chains, jobs, their inputs and
# parameters, targets) comes from the plan (chain.pipeline.plan.run_plan.RunPlan); the
# rules are made from its steps (steps.smk).

import importlib.util
import os
import sys
from pathlib import Path

from snakemake import __version__ as SNAKEMAKE_VERSION
from snakemake.exceptions import WorkflowError
from snakemake.scheduling.job_scheduler import JobScheduler

from chain.pipeline.config.check import check_config
from chain.pipeline.plan.code import remember_imports, save_imports, script_sources
from chain.pipeline.plan.datasets import DEFAULT_CACHE, check_experiment_datasets
from chain.pipeline.plan.run_plan import RunPlan
from chain.pipeline.provenance.record import run_provenance
from chain.pipeline.run.checksums import remove_checksums
from chain.pipeline.run.reuse import Reuse
from chain.pipeline.run.snakemake_patches import patch_snakemake
from chain.pipeline.run.store import Store, StoreError

check_config(config)

# The code each job runs is an input of its rule: its script, the script's local helpers
# and every chain module it imports (chain.pipeline.plan.code), so editing the physics
# reruns the simulations, and one figure's module redraws that figure only. Paths
# relative to the working directory: a moved or copied checkout has nothing to do.
# PACKAGE_DIR is the package the jobs import (src/chain, or PYTHONPATH's copy). The
# import statements are remembered by file version between runs (prepare_run).
PACKAGE_DIR = Path(importlib.util.find_spec("chain").origin).parent
IMPORTS_STORE = DEFAULT_CACHE.parent / "imports.json"
remember_imports(IMPORTS_STORE)


def code(script):
    """workflow/scripts/<script>.py and the source files it runs."""
    path = Path(workflow.basedir, "workflow", "scripts", f"{script}.py")
    return [os.path.relpath(path), *script_sources(path, PACKAGE_DIR)]


PLAN = RunPlan(
    config,
    code=code,
    workflow_dir=os.path.relpath(workflow.basedir),
    # Commit, config hash and installed versions (summary.json and the article).
    provenance=run_provenance(config, workflow.basedir),
)
OUT = PLAN.out
ENV = "../envs/hertzchain.yaml"
for line in PLAN.notes() if workflow.is_main_process else []:
    print(line, file=sys.stderr)
# Every shot file of every measured dataset, now: all problems on the console at once,
# before any job (verdicts cached by file content).
check_experiment_datasets(config, list(PLAN.experiment.chains))

# The result store: its whole path checked here, before any job (made when a run needs
# it); chain.pipeline.run.reuse decides what the run takes from it.
try:
    STORE = Store.open(os.environ, create=False) if config["reuse"] else None
except StoreError as error:
    raise WorkflowError(str(error)) from None
REUSE = Reuse(PLAN, STORE)
# Snakemake's scheduler, patched on the release the patches were written for
# (chain.pipeline.run.snakemake_patches); any other release says so in one line.
for line in patch_snakemake(JobScheduler, SNAKEMAKE_VERSION):
    if workflow.is_main_process:
        print(line, file=sys.stderr)


def prepare_run():
    """The store's part before the first job, once, in the process that runs the
    workflow (not a cluster job's, not a report's): called by the first input function
    Snakemake evaluates, as it builds the DAG of a run or a dry run."""
    global STORE
    if (
        REUSE.prepared
        or not workflow.is_main_process
        or workflow.executor_plugin is None
    ):
        return
    if workflow.touch:
        return
    asked = workflow.dag_settings
    forced = asked.forceall or bool(asked.forcerun) or bool(asked.forcetargets)
    if config["reuse"] and STORE is None and not workflow.dryrun:
        try:
            REUSE.store = STORE = Store.open(os.environ)
        except StoreError as error:
            raise WorkflowError(str(error)) from None
    targets = PLAN.target_files(asked.targets)
    for line in REUSE.prepare(targets, dry=workflow.dryrun, forced=forced):
        print(line, flush=True)
    if not workflow.dryrun:  # the import statements code() read, for the next command
        save_imports(IMPORTS_STORE)


def job_inputs(rule):
    """The input function of a step's rule: its job's inputs, from the plan."""

    def inputs(wildcards):
        prepare_run()
        job = PLAN.jobs.of(rule, wildcards)
        return {name: REUSE.located(paths) for name, paths in job.inputs.items()}

    return inputs


def target_inputs(rule):
    """The input function of a rule that gathers files (all, ablation, mechanisms)."""

    def inputs(wildcards):
        prepare_run()
        return REUSE.located(PLAN.target_rules()[rule])

    return inputs


# ---- the rules of the plan's steps (steps.smk) ----------------------------------------


def caption(name):
    """A report caption: workflow/report/<name>, or the generic figure caption."""
    own = Path(workflow.basedir, "workflow", "report", name)
    return f"../report/{name if own.exists() else 'figure.rst'}"


def step_outputs(step):
    """(positional, named) outputs of a step, flagged for the report or as folders."""
    flagged = {}
    for name, path in step.outputs.items():
        if name in step.folders:
            path = directory(path)
        if name in step.report:
            file, category = step.report[name]
            path = report(path, caption=caption(file), category=category)
        flagged[name] = path
    positional = [p for n, p in flagged.items() if not n.isidentifier()]
    return positional, {n: p for n, p in flagged.items() if n.isidentifier()}


def step_params(step):
    """Parameter name -> function of the wildcards, for each parameter of the step; and
    the script's name, which names the script file when the job runs (Snakemake reads
    the script directive again then, long after this loop has moved on)."""
    names = PLAN.jobs.of(step.name, step.jobs[0]).params
    params = {
        name: lambda wildcards, n=name, s=step.name: PLAN.jobs.of(s, wildcards).params[
            n
        ]
        for name in names
    }
    return {**params, "script": step.script_name}


def step_benchmark(step):
    """Snakemake's record of the job's time and memory, beside its log's place."""
    log = os.path.relpath(step.log, f"{OUT}/logs")
    return f"{OUT}/benchmarks/{os.path.splitext(log)[0]}.tsv"


onstart:
    remove_checksums(OUT)


onsuccess:
    for line in REUSE.finish(succeeded=True):
        print(line)


onerror:
    for line in REUSE.finish(succeeded=False):
        print(line)
