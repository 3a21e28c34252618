"""One ablation variant of the virtual experiment (a model), all its replicates
(chain.pipeline.ablation.run_variant_tables): delay fits, and SSW fits at S2."""

import pandas as pd
from _logging import start

from chain.atomic import write_csv_atomic
from chain.pipeline.ablation import run_variant_tables

log = start(snakemake)
p = snakemake.params
tables, ssw_tables = [], []
for replicate, chains in enumerate(p.settings):
    fits, ssw_fits = run_variant_tables(chains, p.tolerance, p.estimators, series=p.series)
    seeds = [c["seed"] for c in chains]
    pooled = fits[fits["N"].astype(str) == "pooled"].iloc[0]
    log.info(
        "%s replicate %d (seeds %s): C = %.2f +- %.2f us N^1/6, exponent %.4f +- %.4f",
        snakemake.wildcards.variant,
        replicate,
        seeds,
        pooled["C_us_N16"],
        pooled["C_stderr_us_N16"],
        pooled["exponent"],
        pooled["exponent_stderr"],
    )
    tables.append(fits.assign(replicate=replicate, seeds=" ".join(map(str, seeds))))
    ssw_tables.append(ssw_fits.assign(replicate=replicate))
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output.fits)
write_csv_atomic(pd.concat(ssw_tables, ignore_index=True), snakemake.output.ssw_fits)
