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
    priority: 3
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB (270 peak)
        runtime=30,  # minutes
    params:
        settings=lambda w: PLAN.experiment.settings(int(w.N)),
        dataset=PLAN.experiment.series,
    script:
        "../scripts/virtual_experiment.py"


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
    priority: 3
    conda:
        ENV
    params:
        **PLAN.experiment.loading,
    script:
        "../scripts/experiment_traces.py"


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
    priority: 2
    conda:
        ENV
    params:
        **PLAN.experiment.loading,
        tolerance=config["experiment"]["tolerance"],
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/selection.py"


if PLAN.experiment.chains:
    publish("experiment/selection.csv", "selection", "table")
