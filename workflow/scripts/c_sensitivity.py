"""C and the free exponent per choice of estimator, eta, sensor pair and amplitude range
(chain.studies.c_sensitivity), the run's main estimator the headline one, on the shots
the study's simulations recorded (input readings: every bead's force)."""

from _logging import done, start

from chain.apparatus.readings import readings_table
from chain.atomic import write_csv_atomic
from chain.studies.c_sensitivity import c_sensitivity_table

log = start(snakemake)
p = snakemake.params
# One trace table per eta and chain, every sensor bead of every pair: eta (s) -> N -> table.
traces = {}
for job, path in zip(p.jobs, snakemake.input.readings, strict=True):
    table = readings_table(path, job["sensors"], model_name=job["model"])
    traces.setdefault(job["eta_s"], {})[job["N"]] = table
table = c_sensitivity_table(traces, p.plan)
columns = ["choice", "value", "C", "C_stderr", "exponent"]
for row in table[table["N"].astype(str) == "pooled"][columns].itertuples(index=False):
    log.info("%s = %s: C = %.2f +- %.2f, p = %.4f", *row)
write_csv_atomic(table, snakemake.output.table)
done(snakemake)
