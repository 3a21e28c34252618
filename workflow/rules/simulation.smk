# The simulation: one job per model and chain integrates the collision and reference
# shots of every launch speed and records the sensor beads (simulate); each chain's
# collisions again with every contact recorded, the SSW tracked contact by contact, the
# long chains of long_chains too (ssw_track); the collision the space-time figure shows,
# every contact recorded (ssw_fields).


rule simulate:
    output:
        traces=stored("simulate", "simulation/{model}_N{N}_traces.csv", "{model}_N{N}"),
        runs=stored("simulate", "simulation/{model}_N{N}_runs.csv", "{model}_N{N}"),
        sums=stored("simulate", "SHA256SUMS", "{model}_N{N}"),
    log:
        stored("simulate", "log", "{model}_N{N}"),
    benchmark:
        stored("simulate", "benchmark.tsv", "{model}_N{N}")
    # First: the pulse table waits for them; the first chain of each model ahead of the
    # others, so that the kernels compile side by side on a fresh clone.
    priority: lambda w: 4 if int(w.N) == next(iter(PLAN.chains)) else 3
    conda:
        ENV
    threads: lambda w: PLAN.simulation.threads(w)
    resources:
        mem_mb=PLAN.simulation.mem_mb,
        runtime=PLAN.simulation.runtime,
    params:
        job=lambda w: PLAN.simulate_job(w.model, int(w.N)),
    script:
        "../scripts/simulate.py"


# Half a simulate job's work: its requests are an upper bound.
rule ssw_track:
    output:
        track=stored(
            "ssw_track", "simulation/{model}_N{N}_ssw_track.csv", "{model}_N{N}"
        ),
        sums=stored("ssw_track", "SHA256SUMS", "{model}_N{N}"),
    log:
        stored("ssw_track", "log", "{model}_N{N}"),
    benchmark:
        stored("ssw_track", "benchmark.tsv", "{model}_N{N}")
    priority: 3
    conda:
        ENV
    threads: lambda w: PLAN.simulation.threads(w)
    resources:
        mem_mb=PLAN.simulation.mem_mb,
        runtime=PLAN.simulation.runtime,
    params:
        job=lambda w: PLAN.simulate_job(w.model, int(w.N)),
    script:
        "../scripts/ssw_track.py"


# The one collision per chain that the space-time figure shows, integrated again at
# ssw_track's step (the same numbers bit for bit).
rule ssw_fields:
    input:
        tracks=lambda w: [
            output_of("ssw_track", "track", model=PLAN.simulation.spacetime_model, N=n)
            for n in PLAN.simulation.field_chains
        ],
    output:
        **{
            f"N{n}": stored("ssw_fields", f"simulation/{model}_N{n}_field.csv")
            for model in [PLAN.simulation.spacetime_model]
            for n in PLAN.simulation.field_chains
        },
        sums=stored("ssw_fields", "SHA256SUMS"),
    log:
        stored("ssw_fields", "log"),
    benchmark:
        stored("ssw_fields", "benchmark.tsv")
    priority: 3
    conda:
        ENV
    params:
        jobs=lambda w: [
            PLAN.simulate_job(PLAN.simulation.spacetime_model, n)
            for n in PLAN.simulation.field_chains
        ],
        representative_force_N=config["figures"]["representative_force_N"],
        representative_index=config["figures"]["representative_index"],
    script:
        "../scripts/ssw_fields.py"
