"""One ablation variant of the virtual experiment (a model), all its replicates: delay
fits and SSW fits at S2 with every estimator of the run (chain.studies.ablation). A
replicate with the run's own settings reads the run's virtual experiment (input
datasets, where params reads_run says so) instead of simulating it again."""

import pandas as pd
from _logging import done, start

from chain.analysis.rows import of_estimator
from chain.atomic import write_csv_atomic
from chain.studies.ablation import run_variant_shots, variant_fits

log = start(snakemake)
p = snakemake.params
tables, ssw_tables = [], []
for replicate, (chains, reads_run) in enumerate(zip(p.settings, p.reads_run, strict=True)):
    datasets = list(snakemake.input.datasets) if reads_run else []
    if datasets:
        log.info("replicate %d: the run's virtual experiment, %s", replicate, datasets)
    traces, pulses, _ = run_variant_shots(
        chains, None, p.estimators, series=p.series, datasets=datasets
    )
    fits, ssw_fits = variant_fits(traces, pulses, p.tolerance, p.estimators)
    seeds = [c["seed"] for c in chains]
    first = of_estimator(fits, p.estimators[0])
    pooled = first[first["N"].astype(str) == "pooled"].iloc[0]
    log.info(
        "%s replicate %d (seeds %s), %s: C = %.2f +- %.2f us N^1/6, exponent %.4f +- %.4f",
        *(snakemake.wildcards.variant, replicate, seeds, p.estimators[0]),
        *pooled[["C_us_N16", "C_stderr_us_N16", "exponent", "exponent_stderr"]],
    )
    tables.append(fits.assign(replicate=replicate, seeds=" ".join(map(str, seeds))))
    ssw_tables.append(ssw_fits.assign(replicate=replicate))
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output.fits)
write_csv_atomic(pd.concat(ssw_tables, ignore_index=True), snakemake.output.ssw_fits)
done(snakemake)
