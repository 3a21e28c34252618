# The simulation: one job per model and chain integrates the collision and reference
# shots of every launch speed once, every contact recorded, and writes what the rest
# of the run reads of them: the sensor traces, the runs, the SSW tracked contact by
# contact, the collisions' field pooled for the space-time figure, and every bead's
# felt force (simulate); the collisions of the long chains of long_chains, tracked
# (long_chain).


rule simulate:
    output:
        traces=stored("simulate", "simulation/{model}_N{N}_traces.csv", "{model}_N{N}"),
        runs=stored("simulate", "simulation/{model}_N{N}_runs.csv", "{model}_N{N}"),
        track=stored(
            "simulate", "simulation/{model}_N{N}_ssw_track.csv", "{model}_N{N}"
        ),
        field=stored("simulate", "simulation/{model}_N{N}_field.npz", "{model}_N{N}"),
        readings=stored(
            "simulate", "simulation/{model}_N{N}_readings.npz", "{model}_N{N}"
        ),
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


rule long_chain:
    output:
        track=stored(
            "long_chain", "simulation/{model}_N{N}_ssw_track.csv", "{model}_N{N}"
        ),
        field=stored("long_chain", "simulation/{model}_N{N}_field.npz", "{model}_N{N}"),
        sums=stored("long_chain", "SHA256SUMS", "{model}_N{N}"),
    log:
        stored("long_chain", "log", "{model}_N{N}"),
    benchmark:
        stored("long_chain", "benchmark.tsv", "{model}_N{N}")
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
        "../scripts/long_chain.py"
