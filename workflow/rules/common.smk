# Shared definitions: config checks, output paths, the library files each stage
# depends on, and the lists of targets. Other rule files only use names from here.

import importlib.util
from pathlib import Path

import numpy as np

from chain.config_checks import check_config

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

# The library that the jobs import: its source files are inputs of the rules that
# use them, so editing the physics reruns the simulations, editing the analysis
# reruns the tables, and editing figures.py only redraws.
# (Not `import chain`: the name would shadow a Snakemake global.)
LIB = Path(importlib.util.find_spec("chain").origin).parent


def lib(*modules):
    return [str(LIB / f"{module}.py") for module in modules]


# Each list: the modules the rule's script calls and what they import.
LIB_SIMULATE = lib("materials", "model", "integrator", "simulation", "theory", "traces")
LIB_PULSES = lib("materials", "traces", "pulses")
LIB_DELAYS = LIB_PULSES + lib("regression", "delays")
LIB_SSW = LIB_DELAYS + lib("ssw")
LIB_SUMMARY = lib("materials", "theory", "summary")
LIB_FIGURES = LIB_SUMMARY + lib("traces", "figures")


# ---- trace sources -------------------------------------------------------------
# A "part" is one trace file: (source, model, N). The simulation gives one per
# model and chain; the analysis reads them all.
SIMULATION_PARTS = [("simulation", model, n) for model in MODELS for n in CHAINS]

# Experiment traces (virtual or measured, issue 5) plug in here, from a rule file
# workflow/rules/experiment.smk included in the Snakefile (anywhere after common.smk:
# everything below is read through functions, at DAG time):
#   * rules writing trace_file("experiment", <dataset>, N) (chain.traces format) for
#     each chain, and append ("experiment", <dataset>, N) to EXPERIMENT_PARTS;
#   * optionally a rule writing chain.protocol.select_shots' table, its path appended
#     to SELECTION (the delay and SSW tables then drop rejected collision shots);
#   * EXPERIMENT_LABEL = "virtual experiment (model)" when the traces come from the
#     model of the apparatus (figures and summary.md name the series with it);
#   * its config keys added to workflow/schemas/config.schema.yaml.
# Then Fig. 2 joins rule all, and Fig. 4/5 and the summary show the experiment series.
EXPERIMENT_PARTS = []
SELECTION = []
EXPERIMENT_LABEL = "experiment"


def selection_files(wildcards):
    return list(SELECTION)


def experiment_label(wildcards):
    return EXPERIMENT_LABEL


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
    ]
    if EXPERIMENT_PARTS:
        names.insert(1, "fig2_experiment_traces")
    if config["figures"]["parity_ssw_vs_N"]:
        names.append("fig_parity_ssw_vs_N")
    return names


def final_targets(wildcards=None):
    tables = ["pulses", "delays", "delay_fits", "ssw", "ssw_fits"]
    return (
        [f"{TABLES}/{table}.csv" for table in tables]
        + [path for name in figure_names() for path in figure(name)]
        + [f"{OUT}/summary.json", f"{OUT}/summary.md"]
    )
