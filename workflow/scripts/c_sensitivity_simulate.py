"""One simulation of the C-sensitivity study whose eta no configured model has: every
bead's felt force (chain.apparatus.shots.save_readings), for its shifted sensors."""

from _logging import done, start

from chain.apparatus.shots import save_readings, simulate_launches
from chain.pipeline.plan.jobs import chain_of, simulation_kwargs

log = start(snakemake)
job = snakemake.params.job
log.info("eta = %g s, N = %d", job["eta_s"], job["N"])
save_readings(
    simulate_launches(chain_of(job), job["speeds_m_s"], **simulation_kwargs(job)),
    snakemake.output.readings,
)
done(snakemake)
