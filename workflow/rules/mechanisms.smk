# The mechanism study (models, not data): why are the measured SSW larger? On the
# optional LAMMPS engine, the frictionless 1D cross-check against our kernel
# (tables/lammps_check.csv) and one job per (setting, chain) of the friction/rotation
# sweep and of a viscous inter-bead force; beside them the virtual experiment's
# candidates (the ablation variants that name a mechanism). tables/ssw_mechanisms.csv
# and its figure gather the default run's settings; studies.mechanisms: full adds all of
# them (tables/ssw_mechanisms_all.csv). Without LAMMPS the run leaves its jobs out and
# says so before any job.

from chain.pipeline.plan.mechanisms import MechanismPlan

MECHANISMS = MechanismPlan(PLAN, ABLATION)
for line in MECHANISMS.notes() if workflow.is_main_process else []:
    print(line, file=sys.stderr)


rule lammps_check:
    output:
        table=stored("lammps_check", "lammps/check_every_estimator.csv"),
        sums=stored("lammps_check", "SHA256SUMS"),
    log:
        stored("lammps_check", "log"),
    benchmark:
        stored("lammps_check", "benchmark.tsv")
    params:
        config=MECHANISMS.lammps_config,
        estimators=config["analysis"]["estimators"],
    conda:
        ENV
    script:
        "../scripts/lammps_check.py"


rule lammps_check_table:
    input:
        table=made("lammps_check", "table"),
    output:
        table=stored("lammps_check_table", "tables/lammps_check.csv"),
        sums=stored("lammps_check_table", "SHA256SUMS"),
    log:
        stored("lammps_check_table", "log"),
    benchmark:
        stored("lammps_check_table", "benchmark.tsv")
    params:
        column="estimator",
        estimator=config["analysis"]["main_estimator"],
    conda:
        ENV
    script:
        "../scripts/main_estimator_rows.py"


rule lammps_setting:
    output:
        traces=stored("lammps_setting", "lammps/{setting}_N{N}_traces.csv", "{setting}_N{N}"),
        runs=stored("lammps_setting", "lammps/{setting}_N{N}_runs.csv", "{setting}_N{N}"),
        delay_fits=stored(
            "lammps_setting", "lammps/{setting}_N{N}_delay_fits.csv", "{setting}_N{N}"
        ),
        ssw_fits=stored("lammps_setting", "lammps/{setting}_N{N}_ssw_fits.csv", "{setting}_N{N}"),
        sums=stored("lammps_setting", "SHA256SUMS", "{setting}_N{N}"),
    log:
        stored("lammps_setting", "log", "{setting}_N{N}"),
    benchmark:
        stored("lammps_setting", "benchmark.tsv", "{setting}_N{N}")
    params:
        config=MECHANISMS.lammps_config,
        estimators=config["analysis"]["estimators"],
        sensors=lambda w: list(PLAN.chains[int(w.N)]),
    conda:
        ENV
    script:
        "../scripts/lammps_setting.py"


def setting_fits(group, what):
    """An input function: the fits ``what`` of each setting of ``group`` (lammps or
    viscous) of tables/ssw_mechanisms{,_all}.csv, every chain."""
    return lambda w: [
        output_of("lammps_setting", what, setting=setting, N=n)
        for setting in MECHANISMS.settings(group, full=w.which == "all")
        for n in PLAN.chains
    ]


def candidate_fits(what):
    """An input function: the fits ``what`` of each candidate variant."""
    return lambda w: variant_fits(MECHANISMS.candidates(full=w.which == "all"), what)


rule ssw_mechanisms:
    input:
        lammps_delay_fits=setting_fits("lammps", "delay_fits"),
        lammps_ssw_fits=setting_fits("lammps", "ssw_fits"),
        viscous_delay_fits=setting_fits("viscous", "delay_fits"),
        viscous_ssw_fits=setting_fits("viscous", "ssw_fits"),
        candidate_fits=candidate_fits("fits"),
        candidate_ssw_fits=candidate_fits("ssw_fits"),
    output:
        table=stored("ssw_mechanisms", "tables/ssw_mechanisms.csv", "{which}"),
        sums=stored("ssw_mechanisms", "SHA256SUMS", "{which}"),
    log:
        stored("ssw_mechanisms", "log", "{which}"),
    benchmark:
        stored("ssw_mechanisms", "benchmark.tsv", "{which}")
    params:
        **MECHANISMS.table_params,
        candidates=lambda w: MECHANISMS.candidates(full=w.which == "all"),
        estimator=config["analysis"]["main_estimator"],
    conda:
        ENV
    script:
        "../scripts/ssw_mechanisms.py"


rule fig_ssw_mechanisms:
    input:
        table=made("ssw_mechanisms", "table", which="default"),
    output:
        pdf=stored("fig_ssw_mechanisms", "figures/fig_ssw_mechanisms.pdf"),
        png=report(
            stored("fig_ssw_mechanisms", "figures/fig_ssw_mechanisms.png"),
            caption=caption("fig_ssw_mechanisms"),
            category="Figures",
        ),
        sums=stored("fig_ssw_mechanisms", "SHA256SUMS"),
    log:
        stored("fig_ssw_mechanisms", "log"),
    benchmark:
        stored("fig_ssw_mechanisms", "benchmark.tsv")
    conda:
        ENV
    script:
        "../scripts/fig_ssw_mechanisms.py"


tables = {"table": ("ssw_mechanisms", "table", {"which": "default"})}
if MECHANISMS.lammps:
    publish("tables/lammps_check.csv", "lammps_check_table", "table")
    tables["lammps_check"] = ("lammps_check_table", "table", {})
if MECHANISMS.table_made:
    publish("tables/ssw_mechanisms.csv", "ssw_mechanisms", "table", which="default")
    publish_figure("fig_ssw_mechanisms")
    summarise("ssw_mechanisms", "chain.report.numbers.mechanisms:mechanism_summary", **tables)
if MECHANISMS.full:
    publish("tables/ssw_mechanisms_all.csv", "ssw_mechanisms", "table", which="all")
