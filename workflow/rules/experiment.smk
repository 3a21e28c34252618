# The experiment side (issue 5): experiment traces, virtual or measured, in the trace
# format, and the paper's acceptance protocol on them.
#
#   experiment.source: virtual   virtual_experiment (one job per chain) writes a dataset
#                                in the measured format to experiment/raw/N<N>/ (a MODEL
#                                of the apparatus, labelled "virtual experiment (model)");
#   experiment.source: measured  the dataset folders of experiment.datasets are read
#                                instead (their N and sensors from their metadata.yaml);
#   experiment.source: none      nothing here runs, and Fig. 2 is not drawn.
#
# Then experiment_traces loads the datasets (chain.apparatus.measured.load_dataset) into
# experiment/<name>_N<N>_traces.csv, which the pulses rule analyses with the simulated
# traces; selection applies the 5 % amplitude match (chain.analysis.selection.select_shots) and
# writes experiment/selection.csv, which the delays and ssw rules use to drop rejected
# collision shots. The parts and the label are the plan's (PLAN.experiment).
# Measured datasets are checked when the DAG is built (common.smk); a shot with a dead
# or saturated channel stops the run there, or with experiment.bad_channels: skip is
# left out of the traces and listed in selection.csv with the channel as the reason.


include: "experiment_inputs.smk"


rule virtual_experiment:
    input:
        code("virtual_experiment"),
    output:
        directory(f"{OUT}/experiment/raw/N{{N}}"),
    log:
        f"{LOGS}/experiment/virtual_N{{N}}.log",
    priority: 3
    conda:
        ENV
    # ~1.3 s of integration per chain (40 launches): a second core would shorten it by
    # less than the job another core runs meanwhile.
    threads: 1
    resources:
        mem_mb=1000,  # MB: 270 MB peak
        runtime=30,  # minutes: 2-3 s a chain, up to 170 s compiling on a loaded node
    params:
        settings=virtual_settings,
        dataset=PLAN.virtual_name,
    script:
        "../scripts/virtual_experiment.py"


# One job loads every dataset: a job costs ~2.5 s of Python start-up, a load ~1 s.
rule experiment_traces:
    input:
        virtual=virtual_dataset_folders(),
        measured=measured_dataset_files(),
        lib=code("experiment_traces"),
    output:
        experiment_trace_files(),
    log:
        f"{LOGS}/experiment/traces.log",
    priority: 3
    conda:
        ENV
    params:
        datasets=experiment_datasets(),
        bad_channels=BAD_CHANNELS,
        cache=str(DATASET_CHECK_CACHE),
    script:
        "../scripts/experiment_traces.py"


rule selection:
    input:
        pulses=f"{TABLES}/pulses.csv",
        traces=experiment_trace_files,
        virtual=virtual_dataset_folders(),
        measured=measured_dataset_files(),
        lib=code("selection"),
    output:
        report(
            f"{OUT}/experiment/selection.csv",
            caption="../report/selection.rst",
            category="Tables",
        ),
    log:
        f"{LOGS}/experiment/selection.log",
    priority: 2
    conda:
        ENV
    params:
        tolerance=config["experiment"]["tolerance"],
        estimator=config["analysis"]["main_estimator"],
        datasets=experiment_datasets(),
        bad_channels=BAD_CHANNELS,
        cache=str(DATASET_CHECK_CACHE),
    script:
        "../scripts/selection.py"
