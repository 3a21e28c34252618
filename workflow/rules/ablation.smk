# The ablation study (the virtual experiment, a MODEL, not data): one job per variant of
# ablation.variants reruns the virtual experiment of every chain with one ingredient
# changed (chain.studies.ablation), analyses it as the pipeline analyses the experiment,
# and fits C and a free exponent; ablation_table gathers the variants. The default run
# has the variants marked default_run (tables/ablation_exponent.csv); studies.ablation:
# full adds every variant (tables/ablation_exponent_all.csv). A replicate with the run's
# own settings reads the run's virtual experiment, and a variant whose settings equal
# an earlier one's (its twin) is that one's job.

from chain.pipeline.plan.ablation import AblationPlan

ABLATION = AblationPlan(PLAN)


rule ablation_variant:
    input:
        datasets=lambda w: (
            virtual_datasets(w) if any(ABLATION.reads_run(w.variant)) else []
        ),
    output:
        fits=stored("ablation_variant", "ablation/{variant}_fits.csv", "{variant}"),
        ssw_fits=stored(
            "ablation_variant", "ablation/{variant}_ssw_fits.csv", "{variant}"
        ),
        sums=stored("ablation_variant", "SHA256SUMS", "{variant}"),
    log:
        stored("ablation_variant", "log", "{variant}"),
    benchmark:
        stored("ablation_variant", "benchmark.tsv", "{variant}")
    priority: 1
    conda:
        ENV
    params:
        settings=lambda w: ABLATION.settings(w.variant),
        reads_run=lambda w: ABLATION.reads_run(w.variant),
        tolerance=lambda w: ABLATION.tolerance(w.variant),
        estimators=config["analysis"]["estimators"],
        series=PLAN.experiment.series,
    script:
        "../scripts/ablation_variant.py"


rule ablation_table:
    input:
        fits=lambda w: [
            output_of("ablation_variant", "fits", variant=ABLATION.job(name))
            for name in ABLATION.names(full=w.which == "all")
        ],
    output:
        table=stored("ablation_table", "tables/ablation_exponent.csv", "{which}"),
        sums=stored("ablation_table", "SHA256SUMS", "{which}"),
    log:
        stored("ablation_table", "log", "{which}"),
    benchmark:
        stored("ablation_table", "benchmark.tsv", "{which}")
    conda:
        ENV
    params:
        variants=lambda w: ABLATION.names(full=w.which == "all"),
        estimator=config["analysis"]["main_estimator"],
        overrides=ABLATION.overrides,
    script:
        "../scripts/ablation_table.py"


if ABLATION.names(full=False):
    publish("tables/ablation_exponent.csv", "ablation_table", "table", which="default")
    summarise(
        "ablation",
        "chain.report.numbers.spread:ablation_summary",
        table=("ablation_table", "table", {"which": "default"}),
    )
if ABLATION.full:
    publish("tables/ablation_exponent_all.csv", "ablation_table", "table", which="all")
