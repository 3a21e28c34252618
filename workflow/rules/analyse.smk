# Analysis: pulses (cos^6 fits) of every trace file, then the crossing delays, the
# secondary solitary waves (SSW) and their fits, as the contract tables. The analysis
# takes well under a second per trace file, so each table is one job (a job costs
# ~2 s of Python start-up).


rule pulses:
    input:
        traces=all_trace_files,
        lib=code("pulses"),
    output:
        report(
            f"{TABLES}/pulses.csv", caption="../report/pulses.rst", category="Tables"
        ),
    log:
        f"{LOGS}/tables/pulses.log",
    priority: 2
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB: one trace file at a time, 185 MB peak
        runtime=30,  # minutes: ~2 s per trace file
    params:
        estimators=config["analysis"]["estimators"],
    script:
        "../scripts/pulses.py"


rule delays:
    input:
        pulses=f"{TABLES}/pulses.csv",
        selection=selection_files,
        lib=code("delays"),
    output:
        f"{TABLES}/delays.csv",
    log:
        f"{LOGS}/tables/delays.log",
    priority: 1
    conda:
        ENV
    script:
        "../scripts/delays.py"


rule delay_fits:
    input:
        delays=f"{TABLES}/delays.csv",
        lib=code("delay_fits"),
    output:
        report(
            f"{TABLES}/delay_fits.csv",
            caption="../report/delay_fits.rst",
            category="Tables",
        ),
    log:
        f"{LOGS}/tables/delay_fits.log",
    priority: 1
    conda:
        ENV
    script:
        "../scripts/delay_fits.py"


rule ssw:
    input:
        traces=all_trace_files,
        pulses=f"{TABLES}/pulses.csv",
        selection=selection_files,
        lib=code("ssw"),
    output:
        f"{TABLES}/ssw.csv",
    log:
        f"{LOGS}/tables/ssw.log",
    priority: 2
    conda:
        ENV
    resources:
        mem_mb=1000,  # MB: one trace file at a time, 185 MB peak
        runtime=30,  # minutes: ~2 s per trace file
    params:
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/ssw.py"


rule ssw_fits:
    input:
        ssw=f"{TABLES}/ssw.csv",
        lib=code("ssw_fits"),
    output:
        report(
            f"{TABLES}/ssw_fits.csv",
            caption="../report/ssw_fits.rst",
            category="Tables",
        ),
    log:
        f"{LOGS}/tables/ssw_fits.log",
    priority: 1
    conda:
        ENV
    script:
        "../scripts/ssw_fits.py"


# How much C depends on our choices (issue 13, item 7): estimator, eta, sensor pair,
# amplitude range, one at a time from the headline choice, on shots simulated anew
# (every sensor bead of every pair recorded; chain.studies.c_sensitivity).
# The table for every estimator as the headline one (the simulations are the cost);
# c_sensitivity_table picks the main one.
rule c_sensitivity:
    input:
        code("c_sensitivity"),
    output:
        f"{OUT}/c_sensitivity/every_estimator.csv",
    log:
        f"{LOGS}/c_sensitivity/every_estimator.log",
    priority: 1
    conda:
        ENV
    params:
        plan=PLAN.c_sensitivity_study,
        # Every input of each simulation of the study (RunPlan.c_sensitivity_jobs).
        jobs=PLAN.c_sensitivity_jobs(),
    script:
        "../scripts/c_sensitivity.py"


rule c_sensitivity_table:
    input:
        table=f"{OUT}/c_sensitivity/every_estimator.csv",
        lib=code("main_estimator_rows"),
    output:
        f"{TABLES}/c_sensitivity.csv",
    log:
        f"{LOGS}/tables/c_sensitivity.log",
    conda:
        ENV
    params:
        column="main_estimator",
        estimator=config["analysis"]["main_estimator"],
    script:
        "../scripts/main_estimator_rows.py"


# The SSW as a wave (issue 13): each chain's collisions re-simulated with every contact
# recorded (the simulate rule keeps two sensor readings only), the SSW tracked contact
# by contact; the field of the shot the space-time figure shows is kept. The long chains
# (config long_chains) run here only: collisions in the middle, for the SSW far field.
rule ssw_track:
    input:
        code("ssw_track"),
    output:
        track=f"{OUT}/simulation/{{model}}_N{{N}}_ssw_track.csv",
    log:
        f"{LOGS}/simulate/{{model}}_N{{N}}_ssw_track.log",
    # Before the tables, which wait for it. A local run gives it one thread
    # (profiles/default: set-threads), so that a what-if links the long chains' tracks
    # from the store without waiting for two free cores.
    priority: 3
    conda:
        ENV
    # Half the simulate job's work (collision shots only), same arrays per shot: the
    # simulate job's threads and resources are an upper bound.
    threads: simulate_threads
    resources:
        mem_mb=simulate_mem_mb,
        runtime=simulate_runtime,
    params:
        job=simulate_job,
    script:
        "../scripts/ssw_track.py"


# The collision the space-time figure shows, on each chain it shows (PLAN.field_chains):
# one job integrates that one shot again, every contact recorded, at ssw_track's step
# (the same numbers bit for bit): a figure key picking another collision costs
# milliseconds of integration, not the tracks.
rule ssw_fields:
    input:
        tracks=[
            f"{OUT}/simulation/{PLAN.spacetime_model}_N{n}_ssw_track.csv"
            for n in PLAN.field_chains
        ],
        lib=code("ssw_fields"),
    output:
        **{
            f"N{n}": f"{OUT}/simulation/{PLAN.spacetime_model}_N{n}_field.csv"
            for n in PLAN.field_chains
        },
    log:
        f"{LOGS}/simulate/ssw_fields.log",
    # As soon as the tracks are there: the space-time figure and the article wait for
    # it, and in a figure what-if it is the one job that computes before them.
    priority: 3
    conda:
        ENV
    params:
        jobs=[PLAN.simulate_job(PLAN.spacetime_model, n) for n in PLAN.field_chains],
        representative_force_N=config["figures"]["representative_force_N"],
        representative_index=config["figures"]["representative_index"],
    script:
        "../scripts/ssw_fields.py"


rule ssw_speed:
    input:
        tracks=[
            f"{OUT}/simulation/{model}_N{n}_ssw_track.csv"
            for model in PLAN.models
            for n in PLAN.tracked_chains
        ],
        lib=code("ssw_speed"),
    output:
        track=f"{TABLES}/ssw_track.csv",
        speed=f"{TABLES}/ssw_speed.csv",
    log:
        f"{LOGS}/tables/ssw_speed.log",
    priority: 1
    conda:
        ENV
    params:
        material=config["material"],
        radius_m=config["radius_m"],
    script:
        "../scripts/ssw_speed.py"
