# What every rule file shares. The config's check and plan; the result store, where a
# computing rule writes in a folder named by its recipe's key (stored(); a recipe an
# earlier run computed is found there, and Snakemake starts nothing for it); how one rule
# names another's outputs (made(), output_of()); what the run folder shows (publish()).
# docs/architecture.md, docs/store.md.

import functools
import os
import sys
from pathlib import Path

from snakemake import __version__ as SNAKEMAKE_VERSION
from snakemake.exceptions import WorkflowError
from snakemake.scheduling.job_scheduler import JobScheduler

from chain.pipeline.config.check import check_config
from chain.pipeline.plan.run_plan import RunPlan
from chain.pipeline.provenance.record import run_provenance
from chain.pipeline.run.recipe import Recipes, Wildcards
from chain.pipeline.run.snakemake_patches import patch_snakemake
from chain.pipeline.run.store_path import StoreError, open_store
from chain.trust import open_code_line

check_config(config)

#: The checkout: this file is workflow/rules/common.smk in it.
CHECKOUT = Path(str(workflow.current_basedir)).parents[1]
PLAN = RunPlan(config, provenance=run_provenance(config, CHECKOUT))
OUT = PLAN.out
ENV = "../envs/hertzchain.yaml"
# Every file of the measured datasets checked, before anything is written.
if workflow.is_main_process:
    PLAN.experiment.check_datasets()
#: Commands that run jobs make the store's folder and discard damaged entries; a dry run
#: only reports (its output settings say so while the Snakefile is read; dryrun not yet).
MAKES_FILES = not (workflow.output_settings.dryrun or workflow.dryrun or workflow.touch)
try:
    # A store in a folder of the code the run executes is trusted as that code is.
    CODE = [CHECKOUT, Path(workflow.basedir)]
    STORE = open_store(os.environ, trusted=CODE, create=MAKES_FILES)
except StoreError as error:
    raise WorkflowError(str(error)) from None
RECIPES = Recipes(STORE)

# What is said and checked once, before any job: in the process that runs the workflow,
# not in a cluster job's. Whoever else may write the code may change what the run does.
if workflow.is_main_process:
    for line in filter(None, map(open_code_line, dict.fromkeys(CODE))):
        print(line, file=sys.stderr)
    for line in RECIPES.check_entries(discard_damaged=MAKES_FILES):
        print(line, file=sys.stderr)
    # The scheduler's defects patched on the release the patches were written for
    # (docs/upstream/README.md); any other release says so in one line.
    for line in patch_snakemake(JobScheduler, SNAKEMAKE_VERSION):
        print(line, file=sys.stderr)


def stored(rule, file, label=""):
    """Where the job of ``rule`` with the wildcards of ``label`` keeps ``file``: in its
    folder of the store, named by the rule, the label and its recipe's key."""
    folder = "-".join(part for part in (rule, label, "{key}") if part)
    return f"{STORE}/{folder}/{file}"


def output_of(rule, name, **wildcards):
    """The output ``name`` of the job of ``rule`` with these wildcard values."""
    values = {key: str(value) for key, value in wildcards.items()}
    key = key_of(rule, tuple(sorted(values.items())))
    return str(getattr(rules, rule).output[name]).format(**values, key=key)


def made(rule, name, **wildcards):
    """An input function: the output ``name`` of the job of ``rule`` with these
    wildcard values (found as Snakemake builds its DAG, once every rule is defined)."""
    return lambda _: output_of(rule, name, **wildcards)


@functools.cache
def key_of(rule, wildcards):
    """The key of the job of ``rule`` with ``wildcards`` ((name, value) pairs): its
    script, and its named inputs and params as Snakemake evaluates them for the job."""
    proxy, values = getattr(rules, rule), Wildcards(wildcards)
    inputs = {name: values.evaluate(item) for name, item in proxy.input.items()}
    params = {name: values.evaluate(item) for name, item in proxy.params.items()}
    outputs = [Path(str(path)).name for path in proxy.output]
    script = CHECKOUT / "workflow" / "rules" / proxy.rule.script
    inputs = values.filled(inputs)
    return RECIPES.key(rule, dict(wildcards), script, params, inputs, outputs)


#: The run folder (results/<run_name>): path in it -> (rule, output, wildcards) of the
#: stored file it is a copy of, as each rule file lists them (publish()).
RUN_FOLDER = {}
#: summary.json's sections, as the rule files add them. Name -> (module and function that
#: summarise them, "module:function"; {table name -> (rule, output, wildcards)}).
SUMMARY_PARTS = {}


def publish(path, rule, name, **wildcards):
    """Put the output ``name`` of a job of ``rule`` in the run folder as ``path``."""
    RUN_FOLDER[path] = (rule, name, wildcards)


def publish_figure(rule):
    """The PDF and PNG of the figure drawn by ``rule`` (outputs pdf, png)."""
    for ext in ("pdf", "png"):
        publish(f"figures/{rule}.{ext}", rule, ext)


def summarise(part, function, **tables):
    """Add the section ``part`` to summary.json: ``function`` ("module:function") of
    ``tables`` (name -> (rule, output, wildcards) of a stored table) and the core's."""
    SUMMARY_PARTS[part] = (function, tables)


def run_folder_files():
    """Every file of the run folder, its checksums last."""
    return [f"{OUT}/{path}" for path in RUN_FOLDER] + [f"{OUT}/SHA256SUMS"]


# ---- inputs that several rule files read -------------------------------------------


def trace_files(wildcards=None):
    """Every trace file the analysis reads: the simulation's, then the experiment's."""
    jobs = [{"model": m, "N": n} for m in PLAN.models for n in PLAN.chains]
    return [
        output_of("simulate", "traces", **job) for job in jobs
    ] + experiment_trace_files()


def experiment_trace_files(wildcards=None, shown=()):
    """The experiment's trace files (of the chains ``shown``, or all)."""
    return [
        output_of("experiment_traces", name) for name in PLAN.experiment.shown(shown)
    ]


def virtual_datasets(wildcards=None):
    """The virtual experiment's dataset folders, one per chain it runs."""
    return [
        output_of("virtual_experiment", "dataset", N=n)
        for n in PLAN.experiment.virtual_n
    ]


def selection_files(wildcards=None):
    """[experiment/selection.csv] when the run has an experiment, else []."""
    return [output_of("selection", "table")] if PLAN.experiment.chains else []
