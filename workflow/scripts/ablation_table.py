"""tables/ablation_exponent.csv from every ablation variant's fits of the run's main
estimator (params estimator) (chain.studies.ablation_table.ablation_table)."""

import pandas as pd
from _logging import done, start

from chain.analysis.rows import of_estimator
from chain.atomic import write_csv_atomic
from chain.studies.ablation_table import ablation_table

log = start(snakemake)
p, i = snakemake.params, snakemake.input
fits = {
    name: of_estimator(pd.read_csv(path), p.estimator) for name, path in zip(p.variants, i.fits)
}
table = ablation_table(fits, p.overrides)
log.info("%d rows", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
