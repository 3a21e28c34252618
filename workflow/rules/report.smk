# The summary beside the paper's numbers, and the HTML report.

from chain.studies.mechanism_table import FRICTION_MECHANISM, REFERENCE_MECHANISM


rule summary:
    input:
        delay_fits=f"{TABLES}/delay_fits.csv",
        ssw_fits=f"{TABLES}/ssw_fits.csv",
        c_sensitivity=PLAN.optional_table("c_sensitivity"),
        ablation=PLAN.optional_table("ablation_exponent"),
        mechanisms=PLAN.optional_table("ssw_mechanisms"),
        lammps_check=PLAN.optional_table("lammps_check"),
        pulses=f"{TABLES}/pulses.csv",
        delays=f"{TABLES}/delays.csv",
        ssw=f"{TABLES}/ssw.csv",
        ssw_speed=f"{TABLES}/ssw_speed.csv",
        selection=selection_files,
        runs=[f"{OUT}/simulation/{m}_N{n}_runs.csv" for _, m, n in SIMULATION_PARTS],
        lib=code("summary"),
    output:
        json=f"{OUT}/summary.json",
    log:
        f"{LOGS}/summary.log",
    benchmark:
        f"{BENCH}/summary.tsv"
    conda:
        ENV
    params:
        run_name=RUN,
        material=config["material"],
        radius_m=config["radius_m"],
        conservative_models=list(PLAN.conservative),
        estimator=config["analysis"]["main_estimator"],
        experiment_label=experiment_label,
        tolerance=config["experiment"]["tolerance"],
        friction_mechanism=FRICTION_MECHANISM,
        reference_mechanism=REFERENCE_MECHANISM,
        # The studies the config's `studies` switches off (summary.md and the article
        # say they were not run).
        studies_not_run=PLAN.studies_not_run,
        # Commit, config hash, installed versions and how they compare with the lock.
        provenance=PROVENANCE,
    script:
        "../scripts/summary.py"


# summary.md from summary.json: its own job, so rewording the table reruns nothing else.
rule summary_md:
    input:
        json=f"{OUT}/summary.json",
        lib=code("summary_md"),
    output:
        md=report(
            f"{OUT}/summary.md", caption="../report/summary.rst", category="Summary"
        ),
    log:
        f"{LOGS}/summary_md.log",
    benchmark:
        f"{BENCH}/summary_md.tsv"
    conda:
        ENV
    script:
        "../scripts/summary_md.py"


# `snakemake --cores 2 report` builds everything, then the self-contained HTML report
# (the same as `snakemake --report results/<run_name>/report.html` after a run).
rule report:
    input:
        final_targets,
    output:
        f"{OUT}/report.html",
    log:
        f"{LOGS}/report.log",
    conda:
        ENV
    params:
        snakefile=workflow.main_snakefile,
        configfiles=" ".join(
            f"--configfile {path}" for path in workflow.overwrite_configfiles
        ),
    shell:
        "snakemake --snakefile {params.snakefile} {params.configfiles} "
        "--report {output} --nolock > {log} 2>&1"
