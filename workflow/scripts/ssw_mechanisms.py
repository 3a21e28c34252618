"""tables/ssw_mechanisms.csv: SSW/F_m at S2 and C per mechanism and setting: the LAMMPS
friction/rotation sweep and the virtual experiment's candidates
(chain.studies.mechanism_table). The study's jobs fit every estimator; the run's main
one is taken here (params estimator)."""

import pandas as pd
from _logging import start

from chain.analysis.rows import of_estimator
from chain.atomic import write_csv_atomic
from chain.studies.mechanism_table import (
    FRICTION_MECHANISM,
    VISCOUS_MECHANISM,
    candidate_rows,
    mechanism_rows,
)

log = start(snakemake)
p = snakemake.params
i = snakemake.input


def read(path):
    return of_estimator(pd.read_csv(path), p.estimator)


tables = []
if i.lammps_delay_fits:
    tables.append(
        mechanism_rows(
            FRICTION_MECHANISM,
            p.labels,
            [read(path) for path in i.lammps_delay_fits],
            [read(path) for path in i.lammps_ssw_fits],
            p.lammps_reference,
        )
    )
if i.viscous_delay_fits:
    tables.append(
        mechanism_rows(
            VISCOUS_MECHANISM,
            p.viscous_labels,
            [read(path) for path in [*i.lammps_delay_fits, *i.viscous_delay_fits]],
            [read(path) for path in [*i.lammps_ssw_fits, *i.viscous_ssw_fits]],
            p.lammps_reference,
        )
    )
if p.candidates:
    names = list(p.candidates)
    tables.append(
        candidate_rows(
            {name: tuple(value) for name, value in p.candidates.items()},
            dict(zip(names, map(read, i.candidate_fits))),
            dict(zip(names, map(read, i.candidate_ssw_fits))),
            p.candidate_reference,
        )
    )
table = pd.concat(tables, ignore_index=True)
log.info("%d rows", len(table))
write_csv_atomic(table, snakemake.output[0])
