# The rules that gather files besides the default run (rule all, in the Snakefile): the
# studies' full runs (ablation: every ablation variant, ~3-5 min on 2 cores; mechanisms:
# every LAMMPS setting), and the HTML report of a finished run.


rule ablation:
    input:
        target_inputs("ablation"),


rule mechanisms:
    input:
        target_inputs("mechanisms"),


# `snakemake --cores 2 report` builds everything, then the self-contained HTML report
# (the same as `snakemake --report results/<run_name>/report.html` after a run).
rule report:
    input:
        target_inputs("all"),
    output:
        f"{OUT}/report.html",
    log:
        f"{OUT}/logs/report.log",
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
