"""Every ablation variant the run makes, analysed: delay fits and SSW fits with the main
estimator (chain.studies.ablation) of the shots ablation_shots made; the tables from
the fits as written."""

import pandas as pd
from _logging import done, start

from chain.atomic import write_csv_atomic
from chain.studies.ablation import run_variants
from chain.studies.ablation_table import ablation_table
from chain.traces import load_trace_sets

log = start(snakemake)
p, out = snakemake.params, snakemake.output
fits, ssw_fits = run_variants(p.variants, load_trace_sets(snakemake.input.shots), p.estimator)
write_csv_atomic(fits, out.fits)
write_csv_atomic(ssw_fits, out.ssw_fits)
written = pd.read_csv(out.fits)
for names, path in ((p.table, out.table), (p.table_all, out.table_all)):
    table = ablation_table({n: written[written["variant"] == n] for n in names}, p.overrides)
    log.info("%s: %d rows", path, len(table))
    write_csv_atomic(table, path)
done(snakemake)
