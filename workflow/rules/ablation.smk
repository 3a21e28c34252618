# Ablation of the virtual experiment (issue 13, item 6; a MODEL, not data): one job
# per variant of config `ablation.variants` reruns the virtual experiment of every
# chain with that variant's settings (chain.studies.ablation), analyses it as the
# pipeline analyses the experiment (pulses, 5 % selection, delays) and fits
# |Delta| = C F_m^(-1/6) and a free exponent; ablation_table gathers the variants.
# Variants marked default_run are in the default run (tables/ablation_exponent.csv);
# all of them (~3-5 min on 2 cores): `snakemake --cores 2 ablation`
# (tables/ablation_exponent_all.csv).


include: "ablation_inputs.smk"


rule ablation:
    input:
        f"{TABLES}/ablation_exponent_all.csv",


rule ablation_variant:
    input:
        code("ablation_variant"),
    output:
        fits=f"{OUT}/ablation/{{variant}}_fits.csv",
        ssw_fits=f"{OUT}/ablation/{{variant}}_ssw_fits.csv",
    log:
        f"{LOGS}/ablation/{{variant}}.log",
    cache: REUSE
    priority: 1
    conda:
        ENV
    params:
        settings=ablation_settings,
        tolerance=ablation_tolerance,
        estimators=[config["analysis"]["main_estimator"]],
        series=PLAN.virtual_name,
        software=SOFTWARE,
        variant=restate("variant"),
    script:
        "../scripts/ablation_variant.py"


# The default run's variants (tables/ablation_exponent.csv) and all of them
# (tables/ablation_exponent_all.csv, target `ablation`).
rule ablation_table:
    input:
        fits=lambda wildcards: ablation_fit_files(wildcards.which),
        lib=code("ablation_table"),
    output:
        f"{TABLES}/ablation_exponent{{which}}.csv",
    log:
        f"{LOGS}/tables/ablation_exponent{{which}}.log",
    wildcard_constraints:
        which="|_all",
    cache: REUSE
    conda:
        ENV
    params:
        variants=lambda wildcards: ablation_names(wildcards.which),
        overrides={name: overrides_text(v) for name, v in PLAN.ablation.items()},
        software=SOFTWARE,
        which=restate("which"),
    script:
        "../scripts/ablation_table.py"
