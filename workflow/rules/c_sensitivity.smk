# The C-sensitivity study: how much C depends on our choices (estimator, eta, sensor
# pair, amplitude range, one at a time from the headline choice), on shots simulated
# anew with every sensor bead of every pair recorded (chain.studies.c_sensitivity). One
# job computes the table for every estimator as the headline one (the simulations are
# the cost), so that a what-if choosing another main estimator reuses it;
# c_sensitivity_table picks the main one.

from chain.pipeline.plan.c_sensitivity import CSensitivityPlan

C_SENSITIVITY = CSensitivityPlan(PLAN)


rule c_sensitivity:
    output:
        table=stored("c_sensitivity", "c_sensitivity/every_estimator.csv"),
        sums=stored("c_sensitivity", "SHA256SUMS"),
    log:
        stored("c_sensitivity", "log"),
    benchmark:
        stored("c_sensitivity", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    params:
        plan=C_SENSITIVITY.every_estimator,
        jobs=C_SENSITIVITY.jobs(),
    script:
        "../scripts/c_sensitivity.py"


rule c_sensitivity_table:
    input:
        table=made("c_sensitivity", "table"),
    output:
        table=stored("c_sensitivity_table", "tables/c_sensitivity.csv"),
        sums=stored("c_sensitivity_table", "SHA256SUMS"),
    log:
        stored("c_sensitivity_table", "log"),
    benchmark:
        stored("c_sensitivity_table", "benchmark.tsv")
    conda:
        ENV
    params:
        column="main_estimator",
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/main_estimator_rows.py"


rule fig_c_sensitivity:
    input:
        table=made("c_sensitivity_table", "table"),
    output:
        pdf=stored("fig_c_sensitivity", "figures/fig_c_sensitivity.pdf"),
        png=report(
            stored("fig_c_sensitivity", "figures/fig_c_sensitivity.png"),
            caption="../report/fig_c_sensitivity.rst",
            category="Figures",
        ),
        sums=stored("fig_c_sensitivity", "SHA256SUMS"),
    log:
        stored("fig_c_sensitivity", "log"),
    benchmark:
        stored("fig_c_sensitivity", "benchmark.tsv")
    conda:
        ENV
    script:
        "../scripts/fig_c_sensitivity.py"


if PLAN.study("c_sensitivity"):
    publish("tables/c_sensitivity.csv", "c_sensitivity_table", "table")
    publish_figure("fig_c_sensitivity")
    summarise(
        "c_spread",
        "chain.report.numbers.spread:c_spread_summary",
        table=("c_sensitivity_table", "table", {}),
    )
