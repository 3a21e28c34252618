"""Sweep table: C and SSW slope per model and chain, with each model's eta
(chain.studies.sweep.sweep_table)."""

import pandas as pd
from _logging import done, start

from chain.atomic import write_csv_atomic
from chain.studies.sweep import sweep_table

log = start(snakemake)
fits = pd.read_csv(snakemake.input.delay_fits), pd.read_csv(snakemake.input.ssw_fits)
table = sweep_table(*fits, snakemake.params.eta_s, snakemake.params.estimator)
log.info("%d rows (models x chains)", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
