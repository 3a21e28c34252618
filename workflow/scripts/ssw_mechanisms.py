"""tables/ssw_mechanisms.csv: SSW/F_m at S2 and C of the run's main estimator (params
estimator) per mechanism and setting: the LAMMPS friction/rotation sweep and the virtual
experiment's candidates, from the ablation job's fits (chain.studies.mechanism_table)."""

import pandas as pd
from _logging import done, start

from chain.analysis.rows import of_estimator
from chain.atomic import write_csv_atomic
from chain.labels import FRICTION_MECHANISM, VISCOUS_MECHANISM
from chain.studies.mechanism_table import candidate_rows, mechanism_rows

log = start(snakemake)
p, i = snakemake.params, snakemake.input


def read(paths):
    return [of_estimator(pd.read_csv(path), p.estimator) for path in paths]


# Delay fits and SSW fits of each LAMMPS setting; the viscous rows are read beside them.
lammps = read(i.lammps_delay_fits), read(i.lammps_ssw_fits)
viscous = read(i.viscous_delay_fits), read(i.viscous_ssw_fits)
tables = []
if lammps[0]:
    tables.append(mechanism_rows(FRICTION_MECHANISM, p.labels, *lammps, p.lammps_reference))
if viscous[0]:
    both = [lammps[0] + viscous[0], lammps[1] + viscous[1]]
    tables.append(mechanism_rows(VISCOUS_MECHANISM, p.viscous_labels, *both, p.lammps_reference))
if p.candidates:  # the ablation job's fits of every variant it made, as written
    fits = read([i.candidate_fits, i.candidate_ssw_fits])
    candidates = {name: tuple(value) for name, value in p.candidates.items()}
    tables.append(candidate_rows(candidates, *fits, p.candidate_reference))
table = pd.concat(tables, ignore_index=True)
log.info("%d rows", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
