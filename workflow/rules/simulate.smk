# Simulation: one job per model and chain, every launch speed batched in two
# integrator calls (collision shots +V0/-V0 and reference shots +V0 alone).


include: "simulate_inputs.smk"


# Simulations feed the pulse table, which every later table waits for: they go first.
# On a fresh clone the first job of each model compiles that model's numba kernel (10 s);
# the first chain of every model goes ahead of the others, so that the first jobs
# compile different kernels side by side and the rest load them from numba's cache.
rule simulate:
    input:
        code("simulate"),
    output:
        traces=f"{OUT}/simulation/{{model}}_N{{N}}_traces.csv",
        runs=f"{OUT}/simulation/{{model}}_N{{N}}_runs.csv",
    log:
        f"{LOGS}/simulate/{{model}}_N{{N}}.log",
    # First (3-4, see above), with the virtual experiment (3); long side jobs next (1).
    priority: lambda wildcards: 4 if int(wildcards.N) == next(iter(PLAN.chains)) else 3
    conda:
        ENV
    threads: simulate_threads
    resources:
        mem_mb=simulate_mem_mb,
        runtime=simulate_runtime,
    params:
        # Every input of the job (RunPlan.simulate_job): a changed one reruns it.
        job=simulate_job,
    script:
        "../scripts/simulate.py"
