# Figures: one rule, one script and one module (src/chain/report/figures/<rule>.py) per figure.
# They read tables and traces only, so restyling a figure redraws it and nothing else;
# editing the shared style (report/figures/style.py) redraws every figure.


rule fig1_setup:
    input:
        code("fig1_setup"),
    output:
        **figure_outputs("fig1_setup"),
    log:
        f"{LOGS}/figures/fig1_setup.log",
    conda:
        ENV
    params:
        chains=config["chains"],
        radius_m=config["radius_m"],
        material=config["material"],
        striker_radius_m=config["setup"]["striker_radius_m"],
    script:
        "../scripts/fig1_setup.py"


rule fig2_experiment_traces:
    input:
        traces=fig2_trace_files,
        pulses=f"{TABLES}/pulses.csv",
        ssw=f"{TABLES}/ssw.csv",
        selection=selection_files,
        lib=code("fig2_experiment_traces"),
    output:
        **figure_outputs("fig2_experiment_traces"),
    log:
        f"{LOGS}/figures/fig2_experiment_traces.log",
    conda:
        ENV
    params:
        representative_force_N=config["figures"]["experiment_force_N"]
        or config["figures"]["representative_force_N"],
        estimator=config["analysis"]["main_estimator"],
        label=experiment_label,
    script:
        "../scripts/fig2_experiment_traces.py"


rule fig3_simulation_traces:
    input:
        traces=[
            trace_file("simulation", config["figures"]["traces_model"], n)
            for n in PLAN.traces_n
        ],
        pulses=f"{TABLES}/pulses.csv",
        ssw=f"{TABLES}/ssw.csv",
        lib=code("fig3_simulation_traces"),
    output:
        **figure_outputs("fig3_simulation_traces"),
    log:
        f"{LOGS}/figures/fig3_simulation_traces.log",
    conda:
        ENV
    params:
        model=config["figures"]["traces_model"],
        representative_force_N=config["figures"]["representative_force_N"],
        representative_index=config["figures"]["representative_index"],
        estimator=config["analysis"]["main_estimator"],
        label="simulation",
    script:
        "../scripts/fig3_simulation_traces.py"


rule fig4_delay_vs_force:
    input:
        delays=f"{TABLES}/delays.csv",
        fits=f"{TABLES}/delay_fits.csv",
        lib=code("fig4_delay_vs_force"),
    output:
        **figure_outputs("fig4_delay_vs_force"),
    log:
        f"{LOGS}/figures/fig4_delay_vs_force.log",
    conda:
        ENV
    params:
        material=config["material"],
        radius_m=config["radius_m"],
        estimator=config["analysis"]["main_estimator"],
        experiment_label=experiment_label,
    script:
        "../scripts/fig4_delay_vs_force.py"


rule fig5_ssw_vs_force:
    input:
        ssw=f"{TABLES}/ssw.csv",
        fits=f"{TABLES}/ssw_fits.csv",
        track=f"{TABLES}/ssw_track.csv",
        speed=f"{TABLES}/ssw_speed.csv",
        lib=code("fig5_ssw_vs_force"),
    output:
        **figure_outputs("fig5_ssw_vs_force"),
    log:
        f"{LOGS}/figures/fig5_ssw_vs_force.log",
    # The figure at the end of the longest chain of tables (ssw, ssw_fits) and the
    # longest that waits for it: an analysis what-if started it after the shorter
    # figures that were ready at the same time, and ended with it running alone.
    priority: 1
    conda:
        ENV
    params:
        experiment_label=experiment_label,
        sensors={n: list(s) for n, s in PLAN.chains.items()},
    script:
        "../scripts/fig5_ssw_vs_force.py"


rule fig_parity_ssw_vs_N:
    input:
        fits=f"{TABLES}/ssw_fits.csv",
        lib=code("fig_parity_ssw_vs_N"),
    output:
        **figure_outputs("fig_parity_ssw_vs_N"),
    log:
        f"{LOGS}/figures/fig_parity_ssw_vs_N.log",
    conda:
        ENV
    params:
        experiment_label=experiment_label,
    script:
        "../scripts/fig_parity_ssw_vs_N.py"


# The SSW along the chain (issue 13): field of one collision per chain of the first
# conservative model (where the SSW is a clean wave), or of Fig. 3's model if none.
SPACETIME_MODEL = PLAN.spacetime_model


rule ssw_spacetime:
    input:
        fields=[
            f"{OUT}/simulation/{SPACETIME_MODEL}_N{n}_field.csv" for n in PLAN.traces_n
        ],
        long_fields=[
            f"{OUT}/simulation/{SPACETIME_MODEL}_N{n}_field.csv"
            for n in PLAN.long_chains
        ],
        track=f"{TABLES}/ssw_track.csv",
        lib=code("fig_ssw_spacetime"),
    output:
        **figure_outputs("ssw_spacetime"),
    log:
        f"{LOGS}/figures/ssw_spacetime.log",
    # The longest figure: started as soon as its inputs exist, not after the others.
    priority: 1
    conda:
        ENV
    # PDF and PNG drawn at once (chain.report.figures.style.save_figure): the save
    # 5.0 s against 7.3 s, most of it the field's ~3 million cells, drawn per file.
    # Two threads on a cluster; a local run schedules it on one (profiles/default).
    threads: 2
    params:
        model=SPACETIME_MODEL,
        chains=list(PLAN.traces_n),
        long_chains=list(PLAN.long_chains),
    script:
        "../scripts/fig_ssw_spacetime.py"


rule fig_c_sensitivity:
    input:
        table=f"{TABLES}/c_sensitivity.csv",
        lib=code("fig_c_sensitivity"),
    output:
        **figure_outputs("fig_c_sensitivity"),
    log:
        f"{LOGS}/figures/fig_c_sensitivity.log",
    conda:
        ENV
    script:
        "../scripts/fig_c_sensitivity.py"
