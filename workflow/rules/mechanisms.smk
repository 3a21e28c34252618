# The mechanism study (issue 24; models, not data), on the optional LAMMPS engine
# (chain.physics.lammps_engine): the frictionless 1D cross-check against our kernel
# (tables/lammps_check.csv), and the friction/rotation sweep (floor track, gravity,
# track friction mu_t, bead-bead friction mu_b, rolling and twisting resistance), one
# job per (setting, chain), analysed as every series (chain.studies.lammps_sweep), and
# a viscous inter-bead force instead of Kuwabara-Kono on the frictionless track:
# tables/ssw_mechanisms.csv and its figure. The default run runs
# lammps.sweep.default_settings (~30 s on 2 cores); the whole mu_t x mu_b grid:
# `snakemake --cores 2 mechanisms` (tables/ssw_mechanisms_all.csv). Without LAMMPS
# these rules are left out of the default run (common.smk says so on the console).


include: "mechanisms_inputs.smk"


rule mechanisms:
    input:
        f"{TABLES}/ssw_mechanisms_all.csv",


# Every estimator (the simulations are the cost); lammps_check_table picks the main one.
rule lammps_check:
    input:
        code("lammps_check"),
    output:
        f"{OUT}/lammps/check_every_estimator.csv",
    log:
        f"{LOGS}/lammps/check.log",
    conda:
        ENV
    params:
        config=MECHANISM_CONFIG,
        estimators=config["analysis"]["estimators"],
    script:
        "../scripts/lammps_check.py"


rule lammps_check_table:
    input:
        table=f"{OUT}/lammps/check_every_estimator.csv",
        lib=code("main_estimator_rows"),
    output:
        f"{TABLES}/lammps_check.csv",
    log:
        f"{LOGS}/tables/lammps_check.log",
    conda:
        ENV
    params:
        column="estimator",
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/main_estimator_rows.py"


rule lammps_setting:
    input:
        code("lammps_setting"),
    output:
        traces=f"{OUT}/lammps/{{setting}}_N{{N}}_traces.csv",
        runs=f"{OUT}/lammps/{{setting}}_N{{N}}_runs.csv",
        delay_fits=f"{OUT}/lammps/{{setting}}_N{{N}}_delay_fits.csv",
        ssw_fits=f"{OUT}/lammps/{{setting}}_N{{N}}_ssw_fits.csv",
    log:
        f"{LOGS}/lammps/{{setting}}_N{{N}}.log",
    conda:
        ENV
    params:
        config=MECHANISM_CONFIG,
        sensors=lambda wildcards: list(PLAN.chains[int(wildcards.N)]),
        estimators=config["analysis"]["estimators"],
    script:
        "../scripts/lammps_setting.py"


# The default run's settings and candidates (tables/ssw_mechanisms.csv) and all of them
# (tables/ssw_mechanisms_all.csv, target `mechanisms`): the LAMMPS rows when LAMMPS is
# installed, the virtual experiment's candidates (ablation variants with a mechanism)
# when the experiment is virtual.
rule ssw_mechanisms:
    input:
        lammps_delay_fits=lambda wildcards: setting_files(wildcards.which, "delay_fits"),
        lammps_ssw_fits=lambda wildcards: setting_files(wildcards.which, "ssw_fits"),
        viscous_delay_fits=lambda wildcards: setting_files(
            wildcards.which, "viscous_delay_fits"
        ),
        viscous_ssw_fits=lambda wildcards: setting_files(
            wildcards.which, "viscous_ssw_fits"
        ),
        candidate_fits=lambda wildcards: candidate_files(wildcards.which, "fits"),
        candidate_ssw_fits=lambda wildcards: candidate_files(
            wildcards.which, "ssw_fits"
        ),
        lib=code("ssw_mechanisms"),
    output:
        f"{TABLES}/ssw_mechanisms{{which}}.csv",
    log:
        f"{LOGS}/tables/ssw_mechanisms{{which}}.log",
    wildcard_constraints:
        which="|_all",
    conda:
        ENV
    params:
        labels={
            name: setting_label(*pair) for name, pair in PLAN.sweep(full=True).items()
        },
        viscous_labels={
            name: f"gamma={gamma:g} N s/m"
            for name, gamma in PLAN.viscous(full=True).items()
        },
        lammps_reference=PLAN.frictionless,
        candidates=lambda wildcards: candidates_of(wildcards.which),
        candidate_reference=CANDIDATE_REFERENCE,
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/ssw_mechanisms.py"


rule fig_ssw_mechanisms:
    input:
        table=f"{TABLES}/ssw_mechanisms.csv",
        lib=code("fig_ssw_mechanisms"),
    output:
        **figure_outputs("fig_ssw_mechanisms"),
    log:
        f"{LOGS}/figures/fig_ssw_mechanisms.log",
    conda:
        ENV
    script:
        "../scripts/fig_ssw_mechanisms.py"
