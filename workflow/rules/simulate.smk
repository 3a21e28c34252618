# Simulation: one job per model and chain, every launch speed batched in two
# integrator calls (collision shots +V0/-V0 and reference shots +V0 alone).


rule simulate:
    input:
        code("simulate"),
    output:
        traces=f"{OUT}/simulation/{{model}}_N{{N}}_traces.csv",
        runs=f"{OUT}/simulation/{{model}}_N{{N}}_runs.csv",
    log:
        f"{LOGS}/simulate/{{model}}_N{{N}}.log",
    benchmark:
        f"{BENCH}/simulate/{{model}}_N{{N}}.tsv"
    # First (3-4, see simulate_priority), with the virtual experiment (3); long side
    # jobs next (1).
    priority: simulate_priority
    conda:
        ENV
    threads: simulate_threads
    resources:
        mem_mb=simulate_mem_mb,
        runtime=simulate_runtime,
    params:
        material=config["material"],
        radius_m=config["radius_m"],
        eta_s=lambda wildcards: MODELS[wildcards.model]["eta_s"],
        sensors=lambda wildcards: CHAINS[int(wildcards.N)]["sensors"],
        speeds_m_s=SPEEDS,
        simulation=config["simulation"],
    script:
        "../scripts/simulate.py"
