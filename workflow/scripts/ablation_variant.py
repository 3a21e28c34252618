"""One ablation variant of the virtual experiment (a model), all its replicates
(chain.pipeline.ablation.run_variant)."""

import pandas as pd
from _logging import start

from chain.atomic import write_csv_atomic
from chain.pipeline.ablation import run_variant

log = start(snakemake)
p = snakemake.params
tables = []
for replicate, chains in enumerate(p.settings):
    fits = run_variant(chains, p.tolerance, p.estimators, series=p.series)
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
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output[0])
