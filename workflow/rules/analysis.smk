# The analysis: pulses (cos^6 fits) of every trace file, then the crossing delays, the
# secondary solitary waves (SSW) and their fits, and the SSW along the chain, as the
# contract tables. Well under a second per trace file; a table and its fits are one
# job (the fits take milliseconds, a job's start-up a second).


rule pulses:
    input:
        traces=trace_files,
    output:
        table=report(
            stored("pulses", "tables/pulses.csv"),
            caption="../report/pulses.rst",
            category="Tables",
        ),
        sums=stored("pulses", "SHA256SUMS"),
    log:
        stored("pulses", "log"),
    benchmark:
        stored("pulses", "benchmark.tsv")
    priority: 2
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB (185 peak)
        runtime=30,  # minutes (~2 s per trace file)
    params:
        estimators=config["analysis"]["estimators"],
    script:
        "../scripts/pulses.py"


rule delay_fits:
    input:
        pulses=made("pulses", "table"),
        selection=selection_files,
    output:
        delays=stored("delay_fits", "tables/delays.csv"),
        fits=report(
            stored("delay_fits", "tables/delay_fits.csv"),
            caption="../report/delay_fits.rst",
            category="Tables",
        ),
        sums=stored("delay_fits", "SHA256SUMS"),
    log:
        stored("delay_fits", "log"),
    benchmark:
        stored("delay_fits", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    script:
        "../scripts/delay_fits.py"


rule ssw:
    input:
        traces=trace_files,
        pulses=made("pulses", "table"),
        selection=selection_files,
    output:
        ssw=stored("ssw", "tables/ssw.csv"),
        fits=report(
            stored("ssw", "tables/ssw_fits.csv"),
            caption="../report/ssw_fits.rst",
            category="Tables",
        ),
        sums=stored("ssw", "SHA256SUMS"),
    log:
        stored("ssw", "log"),
    benchmark:
        stored("ssw", "benchmark.tsv")
    priority: 2
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB
        runtime=30,  # minutes
    params:
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/ssw.py"


rule ssw_speed:
    input:
        tracks=lambda w: [
            output_of(
                "simulate" if n in PLAN.chains else "long_chain", "track", model=m, N=n
            )
            for m in PLAN.models
            for n in PLAN.tracked_chains
        ],
    output:
        track=stored("ssw_speed", "tables/ssw_track.csv"),
        speed=stored("ssw_speed", "tables/ssw_speed.csv"),
        sums=stored("ssw_speed", "SHA256SUMS"),
    log:
        stored("ssw_speed", "log"),
    benchmark:
        stored("ssw_speed", "benchmark.tsv")
    priority: 1
    conda:
        ENV
    params:
        material=config["material"],
        radius_m=config["radius_m"],
    script:
        "../scripts/ssw_speed.py"


for path, rule, name in [
    ("pulses", "pulses", "table"),
    ("delays", "delay_fits", "delays"),
    ("delay_fits", "delay_fits", "fits"),
    ("ssw", "ssw", "ssw"),
    ("ssw_fits", "ssw", "fits"),
]:
    publish(f"tables/{path}.csv", rule, name)
publish("tables/ssw_track.csv", "ssw_speed", "track")
publish("tables/ssw_speed.csv", "ssw_speed", "speed")
