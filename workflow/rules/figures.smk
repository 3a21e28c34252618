# The paper's figures and the supplementary ones of the core run: each drawn by its own
# rule from tables and traces (restyling a figure never reruns an integrator), its PNG
# in the HTML report, its PDF in the run folder and the article. A study's figures are
# in the study's rule file.


rule fig1_setup:
    output:
        pdf=stored("fig1_setup", "figures/fig1_setup.pdf"),
        png=report(
            stored("fig1_setup", "figures/fig1_setup.png"),
            caption="../report/fig1_setup.rst",
            category="Figures",
        ),
        sums=stored("fig1_setup", "SHA256SUMS"),
    log:
        stored("fig1_setup", "log"),
    benchmark:
        stored("fig1_setup", "benchmark.tsv")
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
        traces=lambda w: experiment_trace_files(
            shown=config["figures"]["traces_N"] or ()
        ),
        pulses=made("pulses", "table"),
        ssw=made("ssw", "ssw"),
        selection=selection_files,
    output:
        pdf=stored("fig2_experiment_traces", "figures/fig2_experiment_traces.pdf"),
        png=report(
            stored("fig2_experiment_traces", "figures/fig2_experiment_traces.png"),
            caption="../report/fig2_experiment_traces.rst",
            category="Figures",
        ),
        sums=stored("fig2_experiment_traces", "SHA256SUMS"),
    log:
        stored("fig2_experiment_traces", "log"),
    benchmark:
        stored("fig2_experiment_traces", "benchmark.tsv")
    conda:
        ENV
    params:
        representative_force_N=config["figures"]["experiment_force_N"]
        or config["figures"]["representative_force_N"],
        estimator=config["analysis"]["main_estimator"],
        label=PLAN.experiment.label,
    script:
        "../scripts/fig2_experiment_traces.py"


rule fig3_simulation_traces:
    input:
        traces=lambda w: [
            output_of(
                "simulate", "traces", model=config["figures"]["traces_model"], N=n
            )
            for n in PLAN.traces_n
        ],
        pulses=made("pulses", "table"),
        ssw=made("ssw", "ssw"),
    output:
        pdf=stored("fig3_simulation_traces", "figures/fig3_simulation_traces.pdf"),
        png=report(
            stored("fig3_simulation_traces", "figures/fig3_simulation_traces.png"),
            caption="../report/fig3_simulation_traces.rst",
            category="Figures",
        ),
        sums=stored("fig3_simulation_traces", "SHA256SUMS"),
    log:
        stored("fig3_simulation_traces", "log"),
    benchmark:
        stored("fig3_simulation_traces", "benchmark.tsv")
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
        delays=made("delay_fits", "delays"),
        fits=made("delay_fits", "fits"),
    output:
        pdf=stored("fig4_delay_vs_force", "figures/fig4_delay_vs_force.pdf"),
        png=report(
            stored("fig4_delay_vs_force", "figures/fig4_delay_vs_force.png"),
            caption="../report/fig4_delay_vs_force.rst",
            category="Figures",
        ),
        sums=stored("fig4_delay_vs_force", "SHA256SUMS"),
    log:
        stored("fig4_delay_vs_force", "log"),
    benchmark:
        stored("fig4_delay_vs_force", "benchmark.tsv")
    conda:
        ENV
    params:
        material=config["material"],
        radius_m=config["radius_m"],
        estimator=config["analysis"]["main_estimator"],
        experiment_label=PLAN.experiment.label,
    script:
        "../scripts/fig4_delay_vs_force.py"


# At the end of the longest chain of tables: started before shorter figures.
rule fig5_ssw_vs_force:
    input:
        ssw=made("ssw", "ssw"),
        fits=made("ssw", "fits"),
        track=made("ssw_speed", "track"),
        speed=made("ssw_speed", "speed"),
    output:
        pdf=stored("fig5_ssw_vs_force", "figures/fig5_ssw_vs_force.pdf"),
        png=report(
            stored("fig5_ssw_vs_force", "figures/fig5_ssw_vs_force.png"),
            caption="../report/fig5_ssw_vs_force.rst",
            category="Figures",
        ),
        sums=stored("fig5_ssw_vs_force", "SHA256SUMS"),
    log:
        stored("fig5_ssw_vs_force", "log"),
    benchmark:
        stored("fig5_ssw_vs_force", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    params:
        experiment_label=PLAN.experiment.label,
        sensors={n: list(s) for n, s in PLAN.chains.items()},
    script:
        "../scripts/fig5_ssw_vs_force.py"


# The longest figure: started as soon as its inputs exist. PDF and PNG are drawn at
# once, in two processes on a cluster (a local run gives it one core: profiles/default).
rule ssw_spacetime:
    input:
        fields=lambda w: [
            output_of("simulate", "field", model=PLAN.simulation.spacetime_model, N=n)
            for n in PLAN.traces_n
        ],
        long_fields=lambda w: [
            output_of(
                "long_chain", "field", model=PLAN.simulation.spacetime_model, N=n
            )
            for n in PLAN.long_chains
        ],
        track=made("ssw_speed", "track"),
    output:
        pdf=stored("ssw_spacetime", "figures/ssw_spacetime.pdf"),
        png=report(
            stored("ssw_spacetime", "figures/ssw_spacetime.png"),
            caption="../report/ssw_spacetime.rst",
            category="Figures",
        ),
        sums=stored("ssw_spacetime", "SHA256SUMS"),
    log:
        stored("ssw_spacetime", "log"),
    benchmark:
        stored("ssw_spacetime", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    threads: 2
    params:
        model=PLAN.simulation.spacetime_model,
        chains=list(PLAN.traces_n),
        long_chains=list(PLAN.long_chains),
        representative_force_N=config["figures"]["representative_force_N"],
        representative_index=config["figures"]["representative_index"],
    script:
        "../scripts/ssw_spacetime.py"


rule fig_parity_ssw_vs_N:
    input:
        fits=made("ssw", "fits"),
    output:
        pdf=stored("fig_parity_ssw_vs_N", "figures/fig_parity_ssw_vs_N.pdf"),
        png=report(
            stored("fig_parity_ssw_vs_N", "figures/fig_parity_ssw_vs_N.png"),
            caption="../report/fig_parity_ssw_vs_N.rst",
            category="Figures",
        ),
        sums=stored("fig_parity_ssw_vs_N", "SHA256SUMS"),
    log:
        stored("fig_parity_ssw_vs_N", "log"),
    benchmark:
        stored("fig_parity_ssw_vs_N", "benchmark.tsv")
    conda:
        ENV
    params:
        experiment_label=PLAN.experiment.label,
    script:
        "../scripts/fig_parity_ssw_vs_N.py"


publish_figure("fig1_setup")
if PLAN.experiment.chains:
    publish_figure("fig2_experiment_traces")
for figure in ("fig3_simulation_traces", "fig4_delay_vs_force", "fig5_ssw_vs_force"):
    publish_figure(figure)
publish_figure("ssw_spacetime")
if config["figures"]["parity_ssw_vs_N"]:
    publish_figure("fig_parity_ssw_vs_N")
