"""Fits of |Delta| = C F_m^(-1/6) and of a free power law (chain.delays.delay_fit_table)."""

import pandas as pd
from _logging import start

from chain.delays import delay_fit_table
from chain.summary import usable_rows
from chain.traces import write_csv_atomic

log = start(snakemake)
delays = pd.read_csv(snakemake.input.delays)
# Flagged (ok False) or NaN rows stay out of the fits; the count goes to the log.
usable = usable_rows(delays, ["F_m_N", "delay_us"], "delay rows")
delays["ok"] = delays.index.isin(usable.index)
table = delay_fit_table(delays)
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
