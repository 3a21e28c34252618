"""Simulate one model on one chain for every launch speed (chain.apparatus.shots)."""

from _logging import done, start

from chain.apparatus.shots import simulate_shots
from chain.atomic import write_csv_atomic
from chain.pipeline.plan.jobs import chain_of, simulation_kwargs
from chain.traces import write_traces

log = start(snakemake)
job = snakemake.params.job
log.info("N = %d, eta = %g s, %d launch speeds", job["N"], job["eta_s"], len(job["speeds_m_s"]))
args = chain_of(job), job["speeds_m_s"], job["sensors"]  # the chain, its launches and sensors
traces, runs = simulate_shots(*args, model_name=job["model"], **simulation_kwargs(job))
log.info("dt = %g s, largest energy drift %.3g", runs["dt_s"].iloc[0], runs["energy_drift"].max())
write_traces(traces, snakemake.output.traces)
write_csv_atomic(runs, snakemake.output.runs)
done(snakemake)
