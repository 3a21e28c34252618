"""The simulations of the C-sensitivity study at an eta no configured model has, every
chain: every bead's felt force (chain.apparatus.readings.save_readings), for its shifted
sensors."""

from _logging import done, start

from chain.apparatus.readings import save_readings
from chain.apparatus.shots import simulate_launches
from chain.pipeline.plan.jobs import chain_of, simulation_kwargs

log = start(snakemake)
for job in snakemake.params.jobs:
    log.info("eta = %g s, N = %d", job["eta_s"], job["N"])
    launches = simulate_launches(chain_of(job), job["speeds_m_s"], **simulation_kwargs(job))
    save_readings(launches, snakemake.output[f"N{job['N']}"])
done(snakemake)
