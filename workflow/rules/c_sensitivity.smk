# The C-sensitivity study: how much C depends on our choices (estimator, eta, sensor
# pair, amplitude range, one at a time from the headline choice, the run's main
# estimator), on simulated shots read at every bead of every sensor pair
# (chain.studies.c_sensitivity): those of a configured model's eta as its simulate job
# recorded them, the others simulated by c_sensitivity_simulate (every chain of an eta
# in one job: a third of a second of work each).

from chain.pipeline.plan.c_sensitivity import CSensitivityPlan

C_SENSITIVITY = CSensitivityPlan(PLAN)


rule c_sensitivity_simulate:
    output:
        **{
            f"N{n}": stored("c_sensitivity_simulate", f"readings_N{n}.npz", "eta{eta}")
            for n in PLAN.chains
        },
        sums=stored("c_sensitivity_simulate", "SHA256SUMS", "eta{eta}"),
    log:
        stored("c_sensitivity_simulate", "log", "eta{eta}"),
    benchmark:
        stored("c_sensitivity_simulate", "benchmark.tsv", "eta{eta}")
    priority: 2
    conda:
        ENV
    params:
        jobs=lambda w: [C_SENSITIVITY.job(w.eta, n) for n in PLAN.chains],
    script:
        "../scripts/c_sensitivity_simulate.py"


rule c_sensitivity:
    input:
        readings=lambda w: [
            output_of(r, o, **wc) for r, o, wc in C_SENSITIVITY.readings()
        ],
    output:
        table=stored("c_sensitivity", "tables/c_sensitivity.csv"),
        sums=stored("c_sensitivity", "SHA256SUMS"),
    log:
        stored("c_sensitivity", "log"),
    benchmark:
        stored("c_sensitivity", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    params:
        plan=C_SENSITIVITY.choices,
        jobs=C_SENSITIVITY.jobs(),
    script:
        "../scripts/c_sensitivity.py"


rule fig_c_sensitivity:
    input:
        table=made("c_sensitivity", "table"),
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
    publish("tables/c_sensitivity.csv", "c_sensitivity", "table")
    publish_figure("fig_c_sensitivity")
    summarise(
        "c_spread",
        "chain.report.numbers.spread:c_spread_summary",
        table=("c_sensitivity", "table", {}),
    )
