"""Fits of SSW amplitude = slope x F_m (chain.ssw.ssw_fit_table)."""

import pandas as pd
from _logging import start

from chain.ssw import ssw_fit_table
from chain.traces import write_csv_atomic

log = start(snakemake)
table = ssw_fit_table(pd.read_csv(snakemake.input.ssw))
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
