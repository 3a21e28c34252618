# The experiment: its traces in the trace format, and the paper's acceptance protocol on
# them. With experiment.source virtual, virtual_experiment writes each chain's dataset
# in the measured format (a MODEL of the apparatus); with measured, the datasets of
# experiment.datasets are read instead (checked before any job, common.smk); with none,
# nothing here runs and Fig. 2 is not drawn.


# ~1.3 s of integration per chain: a second core would shorten it by less than the job
# another core runs meanwhile.
rule virtual_experiment:
    output:
        dataset=directory(stored("virtual_experiment", "raw", "N{N}")),
        sums=stored("virtual_experiment", "SHA256SUMS", "N{N}"),
    log:
        stored("virtual_experiment", "log", "N{N}"),
    benchmark:
        stored("virtual_experiment", "benchmark.tsv", "N{N}")
    params:
        settings=lambda w: PLAN.experiment.settings(int(w.N)),
        dataset=PLAN.experiment.series,
    priority: 3
    resources:
        mem_mb=1000,  # MB (270 peak)
        runtime=30,  # minutes
    conda:
        ENV
    script:
        "../scripts/virtual_experiment.py"


def virtual_datasets(wildcards):
    """The virtual experiment's dataset folders, one per chain it runs."""
    return [output_of("virtual_experiment", "dataset", N=n) for n in PLAN.experiment.virtual_n]


# One job loads every dataset: a job costs more start-up than a load.
rule experiment_traces:
    input:
        virtual=virtual_datasets,
        measured=PLAN.experiment.measured_files,
    output:
        **{
            name: stored("experiment_traces", file)
            for name, file in PLAN.experiment.trace_files.items()
        },
        sums=stored("experiment_traces", "SHA256SUMS"),
    log:
        stored("experiment_traces", "log"),
    benchmark:
        stored("experiment_traces", "benchmark.tsv")
    params:
        **PLAN.experiment.loading,
    priority: 3
    conda:
        ENV
    script:
        "../scripts/experiment_traces.py"


def experiment_trace_files(wildcards=None, shown=()):
    """The experiment's trace files (of the chains ``shown``, or all)."""
    return [output_of("experiment_traces", name) for name in PLAN.experiment.shown(shown)]


rule selection:
    input:
        pulses=made("pulses", "table"),
        traces=experiment_trace_files,
        virtual=virtual_datasets,
        measured=PLAN.experiment.measured_files,
    output:
        table=report(
            stored("selection", "experiment/selection.csv"),
            caption="../report/selection.rst",
            category="Tables",
        ),
        sums=stored("selection", "SHA256SUMS"),
    log:
        stored("selection", "log"),
    benchmark:
        stored("selection", "benchmark.tsv")
    params:
        tolerance=config["experiment"]["tolerance"],
        estimator=config["analysis"]["main_estimator"],
        **PLAN.experiment.loading,
    priority: 2
    conda:
        ENV
    script:
        "../scripts/selection.py"


def selection_files(wildcards=None):
    """[experiment/selection.csv] when the run has an experiment, else []."""
    return [output_of("selection", "table")] if PLAN.experiment.chains else []


if PLAN.experiment.chains:
    publish("experiment/selection.csv", "selection", "table")
