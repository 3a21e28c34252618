# The ablation study (the virtual experiment, a MODEL, not data): ablation_shots reruns,
# in memory, the virtual experiment of every chain with each variant's ingredient
# changed (ablation.variants: the default run's and the mechanism study's candidates;
# with studies.ablation: full, all), each distinct launch integrated once and the shots
# that are the run's read from its datasets; ablation_variants analyses them with the
# main estimator (an analysis what-if integrates nothing), fits C and a free exponent,
# and tabulates tables/ablation_exponent.csv (and, full, ablation_exponent_all.csv).

from chain.pipeline.plan.ablation import AblationPlan

ABLATION = AblationPlan(PLAN)


rule ablation_shots:
    input:
        datasets=virtual_datasets,
    output:
        shots=stored("ablation_shots", "ablation/shots.npz"),
        sums=stored("ablation_shots", "SHA256SUMS"),
    log:
        stored("ablation_shots", "log"),
    benchmark:
        stored("ablation_shots", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB
        runtime=30,  # minutes
    params:
        variants=lambda w: ABLATION.shots(),
        run=lambda w: [PLAN.experiment.settings(n) for n in PLAN.chains],
        series=PLAN.experiment.series,
    script:
        "../scripts/ablation_shots.py"


rule ablation_variants:
    input:
        shots=made("ablation_shots", "shots"),
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
        estimator=config["analysis"]["main_estimator"],
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
