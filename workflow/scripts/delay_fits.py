"""Fits of |Delta| = C F_m^(-1/6) and of a free power law (chain.delays.delay_fit_table)."""

import pandas as pd
from _logging import start

from chain.delays import delay_fit_table
from chain.traces import write_csv_atomic

log = start(snakemake)
table = delay_fit_table(pd.read_csv(snakemake.input.delays))
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
