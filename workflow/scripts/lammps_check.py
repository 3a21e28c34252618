"""LAMMPS against our kernel in the frictionless 1D limit (chain.studies.lammps_check),
with every estimator of the run (rule lammps_check_table picks the main one)."""

from _logging import done, start

from chain.atomic import write_csv_atomic
from chain.studies.lammps_check import run_lammps_check

log = start(snakemake)
table = run_lammps_check(snakemake.params.config, snakemake.params.estimators)
columns = "N model estimator C_kernel C_lammps rel_diff_C max_trace_diff_over_Fm".split()
for row in table[columns].itertuples(index=False):
    log.info("N = %d %s, %s: C kernel %.6f, LAMMPS %.6f (rel %.2g); traces within %.2g F_m", *row)
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
