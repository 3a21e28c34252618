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
# Then experiment_traces loads each dataset (chain.measured.load_dataset) into
# experiment/<name>_N<N>_traces.csv, which the pulses rule analyses with the simulated
# traces; selection applies the 5 % amplitude match (chain.protocol.select_shots) and
# writes experiment/selection.csv, which the delays and ssw rules use to drop rejected
# collision shots. The parts, the label and the input functions are in common.smk.


rule virtual_experiment:
    input:
        LIB_EXPERIMENT,
    output:
        directory(f"{OUT}/experiment/raw/N{{N}}"),
    log:
        f"{LOGS}/experiment/virtual_N{{N}}.log",
    benchmark:
        f"{BENCH}/experiment/virtual_N{{N}}.tsv"
    conda:
        ENV
    params:
        settings=virtual_settings,
        dataset=VIRTUAL_NAME,
    script:
        "../scripts/virtual_experiment.py"


rule experiment_traces:
    input:
        dataset=experiment_dataset_files,
        lib=LIB_MEASURED,
    output:
        f"{OUT}/experiment/{{dataset}}_N{{N}}_traces.csv",
    log:
        f"{LOGS}/experiment/{{dataset}}_N{{N}}_traces.log",
    benchmark:
        f"{BENCH}/experiment/{{dataset}}_N{{N}}_traces.tsv"
    wildcard_constraints:
        dataset="[A-Za-z][A-Za-z0-9_-]*",
    conda:
        ENV
    params:
        folder=experiment_dataset_folder,
    script:
        "../scripts/experiment_traces.py"


rule selection:
    input:
        pulses=f"{TABLES}/pulses.csv",
        traces=experiment_trace_files,
        lib=LIB_SELECTION,
    output:
        report(
            f"{OUT}/experiment/selection.csv",
            caption="../report/selection.rst",
            category="Tables",
        ),
    log:
        f"{LOGS}/experiment/selection.log",
    benchmark:
        f"{BENCH}/experiment/selection.tsv"
    conda:
        ENV
    params:
        tolerance=config["experiment"]["tolerance"],
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/selection.py"
