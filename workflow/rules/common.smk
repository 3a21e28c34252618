# Shared definitions: the config check, the run plan, output paths, the library files
# each stage depends on, and the input functions of more than one rule file. Every fact
# of the config (speeds, chains, jobs, studies, targets) comes from the plan
# (chain.pipeline.plan.RunPlan); each study's helpers sit in its own rule file.

import importlib.util
import os
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.scheduling.job_scheduler import JobScheduler

from chain.pipeline.config import check_config
from chain.pipeline.datasets import (
    DEFAULT_CACHE as DATASET_CHECK_CACHE,
    bad_channel_policy,
    check_experiment_datasets,
)
from chain.pipeline.deps import remember_imports, save_imports, script_sources
from chain.pipeline import job_server
from chain.pipeline.plan import RunPlan
from chain.pipeline.provenance import run_provenance
from chain.pipeline.reuse import (
    CACHE_VARIABLE,
    cache_folder,
    software_versions,
    unhashed_wildcards,
)
from chain.pipeline.graceful_stop import stop_gracefully_off_the_main_thread
from chain.pipeline.run_end import cancel_snakemake_timers
from chain.pipeline.wakeups import coalesce_wakeups

check_config(config)
PLAN = RunPlan(config)


# ---- the job server (chain.pipeline.job_server) ------------------------------------
# A local run's jobs run in children of one process that imported their libraries once
# (pandas, scipy, numba, matplotlib: 1.5-2.5 s a job otherwise). Each job keeps its own
# process, script, log and status, and the same bytes. Not on a cluster (each job on
# its node, as before), nor with HERTZCHAIN_JOB_SERVER=off. Started here, as soon as
# the config passed its check, not in `onstart`: it imports on the other core while
# Snakemake checks the datasets, reads the rules, builds the DAG and links stored
# results (~2 s of one core in a what-if). The jobs learn its address in `onstart`,
# where the run is known to be local; a cluster run stops it there. Not for a dry run;
# a command that runs no job (--lint, --report) or fails a later check ends it with its
# own exit.
def start_job_server():
    return job_server.start(
        Path(workflow.basedir) / "workflow" / "scripts", ".snakemake/job_server.log"
    )


JOB_SERVER = {}
if workflow.is_main_process and not getattr(workflow.output_settings, "dryrun", True):
    JOB_SERVER["server"] = start_job_server()


# ---- reuse across runs (issue 33; chain.pipeline.reuse) ---------------------------
# Each deterministic step is marked `cache` (= REUSE); the workflow profile
# (profiles/default, profiles/slurm) turns Snakemake's between-workflow cache on, and
# this folder is its store: a job whose script, params, code and upstream jobs match one
# any run of this checkout made takes that run's files (symlinks into results/.cache)
# instead of running. `reuse: false` computes everything anew (and stores nothing).
REUSE = config["reuse"]
os.environ[CACHE_VARIABLE] = str(cache_folder(os.environ, Path.cwd()))
Path(os.environ[CACHE_VARIABLE]).mkdir(parents=True, exist_ok=True)
# Versions the provenance hash does not see; a `software` param of each cached rule.
SOFTWARE = software_versions()
# Commit, config hash and installed versions (summary.json and the article state them):
# read once (git, the installed distributions), not once per rule that states them.
PROVENANCE = run_provenance(config, workflow.basedir)


def restate(name):
    """A param holding wildcard `name`: the cache's hash leaves wildcards out."""
    return lambda wildcards: wildcards[name]


def check_reused_rules(rules):
    """Refuse, at parse time, a cached rule that would share results between jobs."""
    problems = unhashed_wildcards(
        (rule.name, rule.wildcard_names, rule.params.keys())
        for rule in rules
        if getattr(rule.cache, "output", False)  # cached: REUSE true, --cache on
    )
    if problems:
        raise WorkflowError("\n".join(problems))


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

# The code each job runs is an input of its rule: the script's local helpers and every
# chain module it imports, read off the import statements (chain.pipeline.deps), so
# editing the physics reruns the simulations, editing one figure's module redraws that
# figure only, and a new import needs no edit here. Paths are relative to the working
# directory, so a moved or copied checkout has nothing to do. PACKAGE_DIR is the
# package the jobs import (a checkout's src/chain, or PYTHONPATH's copy); not found
# with `import chain`: the name would shadow a Snakemake global.
PACKAGE_DIR = Path(importlib.util.find_spec("chain").origin).parent
# The import statements read by an earlier command, by file version (the Snakefile
# saves them after the last rule): every command parses the workflow, a file is read
# again only when it changed. Kept beside the dataset check's verdicts.
IMPORTS_STORE = DATASET_CHECK_CACHE.parent / "imports.json"
remember_imports(IMPORTS_STORE)


def code(script):
    """Source files that workflow/scripts/<script>.py runs, besides itself."""
    return script_sources(
        Path(workflow.basedir) / "workflow" / "scripts" / f"{script}.py", PACKAGE_DIR
    )


# ---- trace files ----------------------------------------------------------------
# A "part" is one trace file: (source, model, N). The simulation gives one per model
# and chain; the experiment one per chain of PLAN.experiment (virtual: written to
# experiment/raw/N<N>/ by the virtual_experiment rule; measured: a dataset folder of
# experiment.datasets). The analysis reads them all.
SIMULATION_PARTS = [("simulation", m, n) for m in PLAN.models for n in PLAN.chains]
EXPERIMENT_PARTS = [("experiment", part.name, part.n_beads) for part in PLAN.experiment]
# Every shot file of every measured dataset, now: all problems on the console at once,
# before any job (verdicts cached by file content in DATASET_CHECK_CACHE).
check_experiment_datasets(config, list(PLAN.experiment))
BAD_CHANNELS = bad_channel_policy(config)
# The 5 % amplitude match of the experiment's collisions (rule selection).
SELECTION = [f"{OUT}/experiment/selection.csv"] if EXPERIMENT_PARTS else []


onstart:
    if workflow.local_exec and workflow.is_main_process:
        if "server" not in JOB_SERVER:  # Snakemake's API without output settings
            JOB_SERVER["server"] = start_job_server()
        job_server.publish(JOB_SERVER["server"])
    else:
        job_server.stop(JOB_SERVER.pop("server", None))


def trace_file(source, model, n):
    return f"{OUT}/{source}/{model}_N{n}_traces.csv"


def all_trace_files(wildcards=None):
    return [trace_file(*part) for part in SIMULATION_PARTS + EXPERIMENT_PARTS]


def experiment_trace_files(wildcards=None):
    return [trace_file(*part) for part in EXPERIMENT_PARTS]


def selection_files(wildcards):
    return list(SELECTION)


def experiment_label(wildcards):
    return PLAN.experiment_label


def runs_files():
    return [f"{OUT}/simulation/{m}_N{n}_runs.csv" for _, m, n in SIMULATION_PARTS]


def simulate_job(wildcards):
    """Every input of one simulate (or ssw_track) job (RunPlan.simulate_job)."""
    return PLAN.simulate_job(wildcards.model, int(wildcards.N))


# ---- figures and targets ---------------------------------------------------------


def figure(name):
    """The PDF and PNG of a figure (contract name without extension)."""
    return [f"{FIGURES}/{name}.pdf", f"{FIGURES}/{name}.png"]


def figure_outputs(name):
    pdf, png = figure(name)
    return {
        "pdf": pdf,
        "png": report(png, caption=f"../report/{name}.rst", category="Figures"),
    }


def final_targets(wildcards=None):
    return PLAN.targets()


# ---- resources (what a batch scheduler is asked for; issue 16) ----------------------
# mem_mb (MB) and runtime (minutes) per job. A plain local run (`--cores 2`) ignores
# them; a SLURM run (profiles/slurm) passes them to sbatch. simulate asks for what its
# chain needs (chain.pipeline.resources: memory ~ N x speeds x duration, measured); the
# rest is measured on the paper run (peak RSS of the script, results/paper/benchmarks,
# plus the job's own Snakemake process, 200 MB, times 1.5) and rounded up.
# Rules not listed take the profile's default-resources.
# Threads: one per ~10 s of estimated integration: the paper's jobs take 1, so two of
# them run at once on 2 cores; a long sweep job more.
def simulate_threads(wildcards):
    return PLAN.simulation_threads(wildcards.model, int(wildcards.N))


def simulate_mem_mb(wildcards, threads):
    return PLAN.simulation_needs(wildcards.model, int(wildcards.N), threads).mem_mb


def simulate_runtime(wildcards, threads):
    return PLAN.simulation_needs(wildcards.model, int(wildcards.N), threads).runtime


# Virtual experiment: 270 MB peak, 2-3 s per chain (up to 170 s compiling numba kernels
# on a loaded machine).
VIRTUAL_EXPERIMENT_JOB = {"mem_mb": 1000, "runtime": 30}
# pulses, ssw: one trace file at a time, 185 MB peak; ~2 s per trace file.
ANALYSIS_JOB = {"mem_mb": 1000, "runtime": 30}


# One pending wake-up of Snakemake's scheduler at a time, not one more per job event
# (chain.pipeline.wakeups: Snakemake's CPU in the tiny run's 53 jobs 10.3 -> 4.5 s).
coalesce_wakeups(JobScheduler)
# SIGTERM (kill PID, a batch system's cancel) stops the run gracefully instead of
# hanging it when it finds the scheduler selecting jobs (chain.pipeline.graceful_stop).
stop_gracefully_off_the_main_thread(JobScheduler)


# cancel_snakemake_timers: Snakemake's scheduler leaves a 1 s timer behind that the
# process would wait for before exiting (chain.pipeline.run_end); with the wake-ups
# coalesced above they are daemon threads, and this is the fallback.
onsuccess:
    job_server.stop(JOB_SERVER.pop("server", None))
    cancel_snakemake_timers()


onerror:
    job_server.stop(JOB_SERVER.pop("server", None))
    cancel_snakemake_timers()
