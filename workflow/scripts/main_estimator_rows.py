"""A study's table for the run's main estimator: its job computed it for every
estimator, tagged in column params.column (chain.analysis.rows.picked)."""

import pandas as pd
from _logging import done, start

from chain.analysis.rows import picked
from chain.atomic import write_csv_atomic

log = start(snakemake)
p = snakemake.params
table = picked(pd.read_csv(snakemake.input.table), p.column, p.estimator)
log.info("%d rows of %s = %s", len(table), p.column, p.estimator)
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
