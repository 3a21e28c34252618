# Ablation of the virtual experiment (issue 13, item 6; a MODEL, not data): one job
# per variant of config `ablation.variants` reruns the virtual experiment of every
# chain with that variant's settings (chain.studies.ablation), analyses it as the
# pipeline analyses the experiment (pulses, 5 % selection, delays) and fits
# |Delta| = C F_m^(-1/6) and a free exponent; ablation_table gathers the variants.
# Variants marked default_run are in the default run (tables/ablation_exponent.csv);
# all of them (~3-5 min on 2 cores): `snakemake --cores 2 ablation`
# (tables/ablation_exponent_all.csv). Simulations are not repeated: a replicate with the
# run's own settings reads the run's virtual experiment, and a variant identical to one
# listed before it copies that one's outputs (RunPlan.ablation_datasets, ablation_twins).


include: "ablation_inputs.smk"


rule ablation:
    input:
        f"{TABLES}/ablation_exponent_all.csv",


# A replicate with the run's own settings (as_configured's first, mechanism_reference,
# no_selection) reads the run's virtual experiment instead of simulating it again.
rule ablation_variant:
    input:
        datasets=ablation_dataset_files,
        lib=code("ablation_variant"),
    output:
        fits=f"{OUT}/ablation/{{variant}}_fits.csv",
        ssw_fits=f"{OUT}/ablation/{{variant}}_ssw_fits.csv",
    log:
        f"{LOGS}/ablation/{{variant}}.log",
    wildcard_constraints:
        variant="|".join(v for v in PLAN.ablation if v not in ABLATION_TWINS)
        or "no-variant",
    priority: 1
    conda:
        ENV
    params:
        settings=ablation_settings,
        reads_run=ablation_reads_run,
        tolerance=ablation_tolerance,
        estimators=config["analysis"]["estimators"],
        series=PLAN.virtual_name,
    script:
        "../scripts/ablation_variant.py"


rule ablation_twin:
    input:
        unpack(twin_outputs),
    output:
        fits=f"{OUT}/ablation/{{variant}}_fits.csv",
        ssw_fits=f"{OUT}/ablation/{{variant}}_ssw_fits.csv",
    log:
        f"{LOGS}/ablation/{{variant}}.log",
    wildcard_constraints:
        variant="|".join(ABLATION_TWINS) or "no-twin",
    conda:
        ENV
    shell:
        "(cp {input.fits} {output.fits} && cp {input.ssw_fits} {output.ssw_fits}) > {log} 2>&1"


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
    conda:
        ENV
    params:
        variants=lambda wildcards: ablation_names(wildcards.which),
        estimator=config["analysis"]["main_estimator"],
        overrides={name: overrides_text(v) for name, v in PLAN.ablation.items()},
    script:
        "../scripts/ablation_table.py"
