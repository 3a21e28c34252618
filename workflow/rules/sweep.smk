# Sweep what-if (issue 16; whatif/sweep.yaml): N over a range and several eta. The table
# tables/sweep.csv joins, per model and chain, C (delay_fits.csv) and the SSW slope
# (ssw_fits.csv) with the model's eta; figures/fig_c_vs_N draws C(N). SSW(N) is the
# parity figure (figures.smk). Both join rule all when figures.sweep_vs_N is set.


rule sweep_table:
    input:
        delay_fits=f"{TABLES}/delay_fits.csv",
        ssw_fits=f"{TABLES}/ssw_fits.csv",
        lib=code("sweep_table"),
    output:
        report(
            f"{TABLES}/sweep.csv",
            caption="../report/sweep_table.rst",
            category="Tables",
        ),
    log:
        f"{LOGS}/tables/sweep.log",
    conda:
        ENV
    params:
        eta_s=PLAN.models,
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/sweep_table.py"


rule fig_c_vs_N:
    input:
        sweep=f"{TABLES}/sweep.csv",
        lib=code("fig_c_vs_N"),
    output:
        **figure_outputs("fig_c_vs_N"),
    log:
        f"{LOGS}/figures/fig_c_vs_N.log",
    conda:
        ENV
    script:
        "../scripts/fig_c_vs_N.py"
