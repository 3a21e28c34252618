"""Fits of SSW amplitude = slope x F_m (chain.ssw.ssw_fit_table)."""

import pandas as pd
from _logging import start

from chain.ssw import ssw_fit_table
from chain.summary import usable_rows
from chain.traces import write_csv_atomic

log = start(snakemake)
ssw = pd.read_csv(snakemake.input.ssw)
# The fitted rows (method residual): flagged (ok False) or NaN ones stay out, counted.
fitted = ssw["method"] == "residual"
usable = usable_rows(ssw[fitted], ["F_m_N", "ssw_N"], "SSW rows (residual)")
ssw.loc[fitted, "ok"] = ssw.index[fitted].isin(usable.index)
table = ssw_fit_table(ssw)
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
