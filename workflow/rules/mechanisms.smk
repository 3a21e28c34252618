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
CANDIDATES = MECHANISMS.candidates(full=False)  # none, or the reference and more
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
    conda:
        ENV
    params:
        config=MECHANISMS.lammps_config,
        estimators=config["analysis"]["estimators"],
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
    conda:
        ENV
    params:
        column="estimator",
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/main_estimator_rows.py"


rule lammps_setting:
    output:
        traces=stored(
            "lammps_setting", "lammps/{setting}_N{N}_traces.csv", "{setting}_N{N}"
        ),
        runs=stored(
            "lammps_setting", "lammps/{setting}_N{N}_runs.csv", "{setting}_N{N}"
        ),
        delay_fits=stored(
            "lammps_setting", "lammps/{setting}_N{N}_delay_fits.csv", "{setting}_N{N}"
        ),
        ssw_fits=stored(
            "lammps_setting", "lammps/{setting}_N{N}_ssw_fits.csv", "{setting}_N{N}"
        ),
        sums=stored("lammps_setting", "SHA256SUMS", "{setting}_N{N}"),
    log:
        stored("lammps_setting", "log", "{setting}_N{N}"),
    benchmark:
        stored("lammps_setting", "benchmark.tsv", "{setting}_N{N}")
    conda:
        ENV
    params:
        config=MECHANISMS.lammps_config,
        estimators=config["analysis"]["estimators"],
        sensors=lambda w: list(PLAN.chains[int(w.N)]),
    script:
        "../scripts/lammps_setting.py"


rule ssw_mechanisms:
    input:
        lammps_delay_fits=lambda w: [
            output_of("lammps_setting", "delay_fits", setting=setting, N=n)
            for setting in MECHANISMS.settings("lammps", full=w.which == "all")
            for n in PLAN.chains
        ],
        lammps_ssw_fits=lambda w: [
            output_of("lammps_setting", "ssw_fits", setting=setting, N=n)
            for setting in MECHANISMS.settings("lammps", full=w.which == "all")
            for n in PLAN.chains
        ],
        viscous_delay_fits=lambda w: [
            output_of("lammps_setting", "delay_fits", setting=setting, N=n)
            for setting in MECHANISMS.settings("viscous", full=w.which == "all")
            for n in PLAN.chains
        ],
        viscous_ssw_fits=lambda w: [
            output_of("lammps_setting", "ssw_fits", setting=setting, N=n)
            for setting in MECHANISMS.settings("viscous", full=w.which == "all")
            for n in PLAN.chains
        ],
        # The ablation job's fits of every variant it made, the candidates' among them.
        candidate_fits=made("ablation_variants", "fits") if CANDIDATES else [],
        candidate_ssw_fits=made("ablation_variants", "ssw_fits") if CANDIDATES else [],
    output:
        table=stored("ssw_mechanisms", "tables/ssw_mechanisms.csv", "{which}"),
        sums=stored("ssw_mechanisms", "SHA256SUMS", "{which}"),
    log:
        stored("ssw_mechanisms", "log", "{which}"),
    benchmark:
        stored("ssw_mechanisms", "benchmark.tsv", "{which}")
    conda:
        ENV
    params:
        **MECHANISMS.table_params,
        candidates=lambda w: MECHANISMS.candidates(full=w.which == "all"),
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/ssw_mechanisms.py"


rule fig_ssw_mechanisms:
    input:
        table=made("ssw_mechanisms", "table", which="default"),
    output:
        pdf=stored("fig_ssw_mechanisms", "figures/fig_ssw_mechanisms.pdf"),
        png=report(
            stored("fig_ssw_mechanisms", "figures/fig_ssw_mechanisms.png"),
            caption="../report/fig_ssw_mechanisms.rst",
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
    summarise(
        "ssw_mechanisms", "chain.report.numbers.mechanisms:mechanism_summary", **tables
    )
if MECHANISMS.full:
    publish("tables/ssw_mechanisms_all.csv", "ssw_mechanisms", "table", which="all")
