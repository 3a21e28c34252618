# The ablation study (the virtual experiment, a MODEL, not data): one job reruns the
# virtual experiment of every chain for each variant the run makes (ablation.variants:
# the default run's, with the mechanism study's candidates; studies.ablation: full, all),
# with one ingredient changed (chain.studies.ablation), in memory; each distinct launch is
# integrated once, and the shots that are the run's virtual experiment's are read from
# its datasets. It analyses them with the main estimator as the pipeline analyses the
# experiment, fits C and a free exponent, and tabulates the default run's variants
# (tables/ablation_exponent.csv) and, with studies.ablation: full, every variant
# (tables/ablation_exponent_all.csv). A job: a few seconds of work, a second of start-up.

from chain.pipeline.plan.ablation import AblationPlan

ABLATION = AblationPlan(PLAN)


rule ablation_variants:
    input:
        datasets=virtual_datasets,
    output:
        fits=stored("ablation_variants", "ablation/fits.csv"),
        ssw_fits=stored("ablation_variants", "ablation/ssw_fits.csv"),
        table=stored("ablation_variants", "tables/ablation_exponent.csv"),
        table_all=stored("ablation_variants", "tables/ablation_exponent_all.csv"),
        sums=stored("ablation_variants", "SHA256SUMS"),
    log:
        stored("ablation_variants", "log"),
    benchmark:
        stored("ablation_variants", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB
        runtime=30,  # minutes
    params:
        variants=lambda w: ABLATION.job(),
        run=lambda w: ABLATION.run,
        estimator=config["analysis"]["main_estimator"],
        series=PLAN.experiment.series,
        table=lambda w: ABLATION.names(full=False),
        table_all=lambda w: ABLATION.names(full=ABLATION.full),
        overrides=ABLATION.overrides,
    script:
        "../scripts/ablation_variants.py"


if ABLATION.names(full=False):
    publish("tables/ablation_exponent.csv", "ablation_variants", "table")
    summarise(
        "ablation",
        "chain.report.numbers.spread:ablation_summary",
        table=("ablation_variants", "table", {}),
    )
if ABLATION.full:
    publish("tables/ablation_exponent_all.csv", "ablation_variants", "table_all")
