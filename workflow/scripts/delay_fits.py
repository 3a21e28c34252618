"""Fits of |Delta| = C F_m^(-1/6) and of a free power law (chain.analysis.recipe)."""

import pandas as pd
from _logging import done, start

from chain.analysis.recipe import fit_delays
from chain.atomic import write_csv_atomic

log = start(snakemake)
delays = pd.read_csv(snakemake.input.delays)
table = fit_delays(delays)
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
