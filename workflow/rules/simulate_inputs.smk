# The simulation's parts (one trace file per model and chain) and what each simulate
# (or ssw_track) job asks a batch scheduler for.

SIMULATION_PARTS = [("simulation", m, n) for m in PLAN.models for n in PLAN.chains]


def all_trace_files(wildcards=None):
    """Every trace file the analysis reads: the simulation's and the experiment's."""
    return [trace_file(*part) for part in SIMULATION_PARTS + EXPERIMENT_PARTS]


# What a batch scheduler is asked for (issue 16; a plain local run ignores it): threads,
# one per ~10 s of estimated integration (the paper's jobs take 1); memory ~ N x speeds
# x duration, MB; runtime, minutes (chain.pipeline.plan.resources). ssw_track asks the same.
def simulate_threads(wildcards):
    return PLAN.simulation_threads(wildcards.model, int(wildcards.N))


def simulate_mem_mb(wildcards, threads):
    return PLAN.simulation_needs(wildcards.model, int(wildcards.N), threads).mem_mb


def simulate_runtime(wildcards, threads):
    return PLAN.simulation_needs(wildcards.model, int(wildcards.N), threads).runtime


def simulate_job(wildcards):
    """Every input of one simulate (or ssw_track) job (RunPlan.simulate_job)."""
    return PLAN.simulate_job(wildcards.model, int(wildcards.N))
