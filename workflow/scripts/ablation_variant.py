"""One ablation variant of the virtual experiment (a model), all its replicates: delay
fits (chain.studies.ablation) and SSW fits at S2 (chain.studies.mechanism_fits). A
replicate with the run's own settings reads the run's virtual experiment (input
datasets, where params reads_run says so) instead of simulating it again."""

import pandas as pd
from _logging import start

from chain.analysis.recipe import fit_pulses
from chain.atomic import write_csv_atomic
from chain.studies.ablation import run_variant_shots
from chain.studies.mechanism_fits import variant_ssw_fits

log = start(snakemake)
p = snakemake.params
tables, ssw_tables = [], []
for replicate, (chains, reads_run) in enumerate(zip(p.settings, p.reads_run, strict=True)):
    datasets = list(snakemake.input.datasets) if reads_run else []
    if datasets:
        log.info("replicate %d: the run's virtual experiment, %s", replicate, datasets)
    traces, pulses, selection = run_variant_shots(
        chains, p.tolerance, p.estimators, series=p.series, datasets=datasets
    )
    fits = fit_pulses(pulses, selection)
    ssw_fits = variant_ssw_fits(traces, pulses, selection, p.estimators[0])
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
