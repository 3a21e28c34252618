"""C and the free exponent per choice of estimator, eta, sensor pair and amplitude range
(chain.studies.c_sensitivity), on simulated shots, with each estimator as the headline
one (rule c_sensitivity_table writes the main one's as tables/c_sensitivity.csv)."""

from _logging import done, start

from chain.apparatus.shots import simulate_shots
from chain.atomic import write_csv_atomic
from chain.pipeline.plan.jobs import chain_of, simulation_kwargs
from chain.studies.c_sensitivity import c_sensitivity_every_estimator

log = start(snakemake)
p = snakemake.params
# One simulation per eta and chain (RunPlan.c_sensitivity_jobs), every sensor bead of
# every pair recorded: eta (s) -> N -> trace table.
traces = {}
for job in p.jobs:
    args = chain_of(job), job["speeds_m_s"], job["sensors"]
    traces.setdefault(job["eta_s"], {})[job["N"]], _ = simulate_shots(
        *args, model_name=job["model"], **simulation_kwargs(job)
    )
    log.info("eta = %g s, N = %d, beads %s simulated", job["eta_s"], job["N"], job["sensors"])
table = c_sensitivity_every_estimator(traces, p.plan)
columns = ["main_estimator", "choice", "value", "C", "C_stderr", "exponent"]
for row in table[table["N"].astype(str) == "pooled"][columns].itertuples(index=False):
    log.info("headline %s; %s = %s: C = %.2f +- %.2f, p = %.4f", *row)
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
