# The sweep (whatif/sweep.yaml: N over a range and several eta), made when
# figures.sweep_vs_N is set: tables/sweep.csv joins, per model and chain, C and the SSW
# slope with the model's eta; fig_c_vs_N draws C(N) (the parity figure SSW(N) is the
# core's, figures.smk).


rule sweep_table:
    input:
        delay_fits=made("delay_fits", "fits"),
        ssw_fits=made("ssw", "fits"),
    output:
        table=report(
            stored("sweep_table", "tables/sweep.csv"),
            caption="../report/sweep_table.rst",
            category="Tables",
        ),
        sums=stored("sweep_table", "SHA256SUMS"),
    log:
        stored("sweep_table", "log"),
    benchmark:
        stored("sweep_table", "benchmark.tsv")
    conda:
        ENV
    params:
        eta_s=PLAN.models,
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/sweep_table.py"


rule fig_c_vs_N:
    input:
        sweep=made("sweep_table", "table"),
    output:
        pdf=stored("fig_c_vs_N", "figures/fig_c_vs_N.pdf"),
        png=report(
            stored("fig_c_vs_N", "figures/fig_c_vs_N.png"),
            caption="../report/fig_c_vs_N.rst",
            category="Figures",
        ),
        sums=stored("fig_c_vs_N", "SHA256SUMS"),
    log:
        stored("fig_c_vs_N", "log"),
    benchmark:
        stored("fig_c_vs_N", "benchmark.tsv")
    conda:
        ENV
    script:
        "../scripts/fig_c_vs_N.py"


if config["figures"]["sweep_vs_N"]:
    publish("tables/sweep.csv", "sweep_table", "table")
    publish_figure("fig_c_vs_N")
