"""Fits of |Delta| = C F_m^(-1/6) and of a free power law (chain.analysis.delays)."""

import pandas as pd
from _logging import start

from chain.analysis.delays import delay_fit_table
from chain.analysis.rows import flag_unusable
from chain.atomic import write_csv_atomic

log = start(snakemake)
delays = pd.read_csv(snakemake.input.delays)
# Flagged (ok False) or NaN rows stay out of the fits; the count goes to the log.
table = delay_fit_table(flag_unusable(delays, ["F_m_N", "delay_us"], "delay rows"))
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
