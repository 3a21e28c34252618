# Shared definitions: config checks, output paths, the library files each stage
# depends on, and the lists of targets. Other rule files only use names from here.

import importlib.util
import sys
from pathlib import Path

import numpy as np

from chain.pipeline.config import (
    VIRTUAL_SERIES,
    check_config,
    experiment_parts,
    long_chain_duration,
    virtual_experiment_settings,
)
from chain.pipeline.config import experiment_label as experiment_label_of
from chain.studies.c_sensitivity import sensitivity_plan
from chain.pipeline.datasets import (
    DEFAULT_CACHE as DATASET_CHECK_CACHE,
    bad_channel_policy,
    check_experiment_datasets,
)
from chain.pipeline.deps import script_sources
from chain.pipeline.resources import simulation_needs, simulation_threads
from chain.physics.materials import get_material
from chain.physics.model import uniform_chain
from chain.physics.lammps_engine import lammps_available
from chain.studies.mechanism_settings import (
    CANDIDATE_REFERENCE,
    candidate_variants,
    setting_label,
    sweep_settings,
    viscous_settings,
)
from chain.studies.mechanism_table import (
    FRICTION_MECHANISM,
    REFERENCE_MECHANISM,
    VISCOUS_MECHANISM,
)
from chain.pipeline.ablation_config import (
    ablation_variants,
    variant_settings,
    variant_tolerance,
)
from chain.studies.ablation_table import overrides_text

check_config(config)


wildcard_constraints:
    source="simulation|experiment",
    model="[A-Za-z][A-Za-z0-9-]*",
    N=r"\d+",


RUN = config["run_name"]
OUT = f"results/{RUN}"
FIGURES = f"{OUT}/figures"
TABLES = f"{OUT}/tables"
LOGS = f"{OUT}/logs"
ENV = "../envs/hertzchain.yaml"
BENCH = f"{OUT}/benchmarks"

MODELS = {m["name"]: m for m in config["models"]}
CHAINS = {c["N"]: c for c in config["chains"]}
# Launch speeds V0, m/s, geometric; rounded so that params are stable text.
SPEEDS = [
    float(f"{v:.12g}")
    for v in np.geomspace(
        config["launch"]["v0_min_m_s"],
        config["launch"]["v0_max_m_s"],
        config["launch"]["count"],
    )
]
# Models without dissipation: their energy drift is the integrator's error.
CONSERVATIVE = [name for name, m in MODELS.items() if m["eta_s"] == 0]
TRACES_N = config["figures"]["traces_N"] or list(CHAINS)
# Long chains (SSW far field): collisions only, every contact recorded, no sensors.
LONG_CHAINS = list(config["long_chains"]["N"])
# Chains whose SSW is tracked contact by contact (rule ssw_track).
TRACKED_N = list(CHAINS) + LONG_CHAINS


def simulated_duration(n):
    """Simulated time of the chain of n beads, s (long chains: in proportion to N)."""
    if n in CHAINS:
        return config["simulation"]["duration_s"]
    return long_chain_duration(config, n)


def chain_sensors(n):
    """Sensor beads of the chain of n beads (none for a long chain)."""
    return CHAINS[n]["sensors"] if n in CHAINS else []


# The code each job runs is an input of its rule: the script's local helpers and every
# chain module it imports, read off the import statements (chain.pipeline.deps), so
# editing the physics reruns the simulations, editing one figure's module redraws that
# figure only, and a new import needs no edit here. Paths are relative to the working
# directory, so a moved or copied checkout has nothing to do. PACKAGE_DIR is the
# package the jobs import (a checkout's src/chain, or PYTHONPATH's copy); not found
# with `import chain`: the name would shadow a Snakemake global.
PACKAGE_DIR = Path(importlib.util.find_spec("chain").origin).parent


def code(script):
    """Source files that workflow/scripts/<script>.py runs, besides itself."""
    return script_sources(
        Path(workflow.basedir) / "workflow" / "scripts" / f"{script}.py", PACKAGE_DIR
    )


# ---- trace sources -------------------------------------------------------------
# A "part" is one trace file: (source, model, N). The simulation gives one per
# model and chain; the analysis reads them all.
SIMULATION_PARTS = [("simulation", model, n) for model in MODELS for n in CHAINS]

# Experiment traces (issue 5; rules in experiment.smk): one part per chain of the
# virtual experiment (its datasets are written to experiment/raw/N<N>/), or one per
# measured dataset folder of experiment.datasets (N and sensors from its metadata.yaml,
# read here: a bad dataset stops the run before any job, naming the key). Their
# selection table (the 5 % amplitude match) feeds the delay and SSW tables; Fig. 2 joins
# rule all; figures and summary name the series with EXPERIMENT_LABEL ("virtual
# experiment (model)" for the model of the apparatus, "measured (<name>)" for data).
EXPERIMENT = {(part.name, part.n_beads): part for part in experiment_parts(config)}
# Every shot file of every measured dataset, now: all problems on the console at once,
# before any job (verdicts cached by file content in DATASET_CHECK_CACHE).
check_experiment_datasets(config, list(EXPERIMENT.values()))
BAD_CHANNELS = bad_channel_policy(config)
EXPERIMENT_PARTS = [("experiment", name, n) for name, n in EXPERIMENT]
SELECTION = [f"{OUT}/experiment/selection.csv"] if EXPERIMENT else []
EXPERIMENT_LABEL = experiment_label_of(list(EXPERIMENT.values()))
VIRTUAL_NAME = config["experiment"]["name"] or VIRTUAL_SERIES


def selection_files(wildcards):
    return list(SELECTION)


def experiment_label(wildcards):
    return EXPERIMENT_LABEL


def raw_dataset(n):
    """Folder of the virtual experiment's dataset of the chain of n beads."""
    return f"{OUT}/experiment/raw/N{n}"


def experiment_datasets():
    """Each experiment dataset: its folder, series name, N and trace file."""
    return [
        {
            "folder": raw_dataset(n) if part.folder is None else part.folder,
            "name": name,
            "N": n,
            "traces": trace_file("experiment", name, n),
        }
        for (name, n), part in EXPERIMENT.items()
    ]


def experiment_dataset_files():
    """What loading the datasets depends on: the virtual experiment's folders, or the
    measured datasets' metadata.yaml and shot files (editing one reloads them)."""
    return [
        path
        for (name, n), part in EXPERIMENT.items()
        for path in ([raw_dataset(n)] if part.folder is None else part.files)
    ]


def virtual_settings(wildcards):
    """chain.apparatus.virtual.VirtualExperiment fields of one chain (plain values)."""
    n = int(wildcards.N)
    return virtual_experiment_settings(config, n, CHAINS[n]["sensors"])


def experiment_trace_files(wildcards=None):
    return [trace_file(*part) for part in EXPERIMENT_PARTS]


def fig2_trace_files(wildcards):
    """Experiment chains shown in Fig. 2: those in figures.traces_N when it is set
    (all of them if it names none), else all."""
    chosen = config["figures"]["traces_N"]
    shown = [part for part in EXPERIMENT_PARTS if not chosen or part[2] in chosen]
    return [trace_file(*part) for part in shown or EXPERIMENT_PARTS]


def trace_file(source, model, n):
    return f"{OUT}/{source}/{model}_N{n}_traces.csv"


def all_parts():
    return SIMULATION_PARTS + EXPERIMENT_PARTS


def all_trace_files(wildcards=None):
    return [trace_file(*part) for part in all_parts()]


def runs_files():
    return [
        f"{OUT}/simulation/{model}_N{n}_runs.csv" for _, model, n in SIMULATION_PARTS
    ]


def figure(name):
    """The PDF and PNG of a figure (contract name without extension)."""
    return [f"{FIGURES}/{name}.pdf", f"{FIGURES}/{name}.png"]


def figure_outputs(name):
    pdf, png = figure(name)
    return {
        "pdf": pdf,
        "png": report(png, caption=f"../report/{name}.rst", category="Figures"),
    }


def figure_names():
    names = [
        "fig1_setup",
        "fig3_simulation_traces",
        "fig4_delay_vs_force",
        "fig5_ssw_vs_force",
        "ssw_spacetime",
        "fig_c_sensitivity",
    ]
    if EXPERIMENT_PARTS:
        names.insert(1, "fig2_experiment_traces")
    if config["figures"]["parity_ssw_vs_N"]:
        names.append("fig_parity_ssw_vs_N")
    if config["figures"]["sweep_vs_N"]:
        names.append("fig_c_vs_N")
    if MECHANISM_TABLES:
        names.append("fig_ssw_mechanisms")
    return names


def final_targets(wildcards=None):
    tables = [
        "pulses",
        "delays",
        "delay_fits",
        "ssw",
        "ssw_fits",
        "ssw_track",
        "ssw_speed",
        "c_sensitivity",
    ]
    return (
        [f"{TABLES}/{table}.csv" for table in tables]
        + ABLATION_TABLES
        + [path for name in figure_names() for path in figure(name)]
        + [f"{OUT}/summary.json", f"{OUT}/summary.md"]
        + [f"{OUT}/article.pdf"]
        + ([f"{TABLES}/sweep.csv"] if config["figures"]["sweep_vs_N"] else [])
        + LAMMPS_TARGETS
        + MECHANISM_TABLES
    )


# ---- resources (what a batch scheduler is asked for; issue 16) ----------------------
# mem_mb (MB) and runtime (minutes) per job. A plain local run (`--cores 2`) ignores
# them; a SLURM run (profiles/slurm) passes them to sbatch. simulate asks for what its
# chain needs (chain.pipeline.resources: memory ~ N x speeds x duration, measured); the
# rest is measured on the paper run (peak RSS of the script, results/paper/benchmarks,
# plus the job's own Snakemake process, 200 MB, times 1.5) and rounded up.
# Rules not listed take the profile's default-resources.
def simulated_chain(wildcards):
    """The ChainModel a simulate (or ssw_track) job integrates."""
    n = int(wildcards.N)
    return uniform_chain(
        n,
        get_material(config["material"]),
        config["radius_m"],
        MODELS[wildcards.model]["eta_s"],
        sensor_beads=(
            chain_sensors(n) if config["simulation"]["readout"] == "sensor" else ()
        ),
    )


def simulate_needs(wildcards, threads):
    sim = config["simulation"]
    return simulation_needs(
        simulated_chain(wildcards),
        len(SPEEDS),
        max(SPEEDS),
        simulated_duration(int(wildcards.N)),
        sim["record_interval_s"],
        sim["time_step_s"],
        threads,
    )


# Threads: one per ~10 s of estimated integration (chain.pipeline.resources): the
# paper's jobs take 1, so two of them run at once on 2 cores; a long sweep job more.
def simulate_threads(wildcards):
    sim = config["simulation"]
    return simulation_threads(
        simulated_chain(wildcards),
        len(SPEEDS),
        max(SPEEDS),
        simulated_duration(int(wildcards.N)),
        sim["time_step_s"],
    )


# Simulations feed the pulse table, which every later table waits for: they go first.
# On a fresh clone the first job of each model compiles that model's numba kernel (10 s);
# the first chain of every model goes ahead of the others, so that the first jobs
# compile different kernels side by side and the rest load them from numba's cache.
def simulate_priority(wildcards):
    first_chain = next(iter(CHAINS))
    return 4 if int(wildcards.N) == first_chain else 3


def simulate_mem_mb(wildcards, threads):
    return simulate_needs(wildcards, threads).mem_mb


def simulate_runtime(wildcards, threads):
    return simulate_needs(wildcards, threads).runtime


# Virtual experiment: 270 MB peak, 2-3 s per chain (up to 170 s compiling numba kernels
# on a loaded machine).
VIRTUAL_EXPERIMENT_JOB = {"mem_mb": 1000, "runtime": 30}
# pulses, ssw: one trace file at a time, 185 MB peak; ~2 s per trace file.
ANALYSIS_JOB = {"mem_mb": 1000, "runtime": 30}


# ---- ablation of the virtual experiment (rules in ablation.smk) -----------------

ABLATION = {v["name"]: v for v in ablation_variants(config)}
# Variants of the default run (ablation.variants[].default_run; cheap ones) go into
# tables/ablation_exponent.csv and the summary; `snakemake ablation` runs them all into
# tables/ablation_exponent_all.csv. Only with the virtual experiment.
VIRTUAL_RUN = config["experiment"]["source"] == "virtual"
# Variants that name a mechanism (and their reference) belong to the mechanism study
# (config mechanism_study; tables/ssw_mechanisms.csv), not to this table's verdict.
STUDY = config.get("mechanism_study", True)
ABLATION_DEFAULT = (
    [
        n
        for n, v in ABLATION.items()
        if v["default_run"] and not v["mechanism"] and n != CANDIDATE_REFERENCE
    ]
    if VIRTUAL_RUN
    else []
)
ABLATION_TABLES = [f"{TABLES}/ablation_exponent.csv"] if ABLATION_DEFAULT else []


wildcard_constraints:
    variant="|".join(ABLATION) or "no-variant",


def ablation_settings(wildcards):
    """Per replicate, the VirtualExperiment fields of every chain of one variant."""
    variant = ABLATION[wildcards.variant]
    return [
        [
            variant_settings(config, variant, n, c["sensors"], k)
            for n, c in CHAINS.items()
        ]
        for k in range(variant["replicates"])
    ]


def ablation_tolerance(wildcards):
    return variant_tolerance(config, ABLATION[wildcards.variant])


def ablation_names(which):
    """Variants of tables/ablation_exponent<which>.csv: "" the default run's, "_all" all."""
    return list(ABLATION) if which == "_all" else ABLATION_DEFAULT


def ablation_fit_files(which):
    return [f"{OUT}/ablation/{name}_fits.csv" for name in ablation_names(which)]


# ---- the mechanism study on LAMMPS (rules in mechanisms.smk) ---------------------
# LAMMPS is an optional extra: its rules join the default run when it is importable,
# and the console says so when it is not (here, before any job).
LAMMPS = STUDY and lammps_available()
if STUDY and not LAMMPS:
    print(
        "hertzchain: LAMMPS is not importable, so the LAMMPS rules are skipped "
        "(tables/lammps_check.csv; the friction/rotation and viscous rows of "
        "tables/ssw_mechanisms.csv, which keeps the virtual experiment's candidates); "
        'install them with  pip install -e ".[lammps]"',
        file=sys.stderr,
    )
# The config keys the LAMMPS jobs read (chain.studies.lammps_check, lammps_sweep).
MECHANISM_CONFIG = {
    key: config[key]
    for key in ("material", "radius_m", "chains", "models", "lammps")
    if key in config
}
SWEEP_DEFAULT = sweep_settings(config, full=False)
SWEEP_ALL = sweep_settings(config, full=True)
# The viscous inter-bead settings (instead of Kuwabara-Kono, frictionless track).
VISCOUS = {
    "": viscous_settings(config, full=False),
    "_all": viscous_settings(config, full=True),
}
FRICTIONLESS = next(iter(SWEEP_DEFAULT))
# The candidates of the virtual experiment (ablation variants with a mechanism).
CANDIDATES = {
    which: (
        candidate_variants(list(ABLATION.values()), which == "_all")
        if VIRTUAL_RUN and STUDY
        else {}
    )
    for which in ("", "_all")
}
LAMMPS_TARGETS = [f"{TABLES}/lammps_check.csv"] if LAMMPS else []
MECHANISM_TABLES = [f"{TABLES}/ssw_mechanisms.csv"] if LAMMPS or CANDIDATES[""] else []


wildcard_constraints:
    setting="|".join([*SWEEP_ALL, *VISCOUS["_all"]]),


def setting_files(which, what):
    """Per-(setting, chain) outputs of the sweep (``what``; ``viscous_<what>`` for the
    viscous settings): "" the default run's, "_all" all; none without LAMMPS."""
    if not LAMMPS:
        return []
    settings = SWEEP_ALL if which == "_all" else SWEEP_DEFAULT
    if what.startswith("viscous_"):
        settings, what = VISCOUS[which], what.removeprefix("viscous_")
    return [f"{OUT}/lammps/{name}_N{n}_{what}.csv" for name in settings for n in CHAINS]


def candidates_of(which):
    """Variant name -> [mechanism, setting] of the candidates of ssw_mechanisms<which>."""
    return {name: list(value) for name, value in CANDIDATES[which].items()}


def candidate_files(which, what):
    """The candidates' ablation outputs (_fits or _ssw_fits), in candidates_of order."""
    return [f"{OUT}/ablation/{name}_{what}.csv" for name in CANDIDATES[which]]
