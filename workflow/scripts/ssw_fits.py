"""Fits of SSW amplitude = slope x F_m (chain.analysis.ssw.ssw_fit_table)."""

import pandas as pd
from _logging import done, start

from chain.analysis.rows import flag_unusable
from chain.analysis.ssw_fits import ssw_fit_table
from chain.atomic import write_csv_atomic

log = start(snakemake)
ssw = pd.read_csv(snakemake.input.ssw)
# The fitted rows (method residual): flagged (ok False) or NaN ones stay out, counted.
fitted = (ssw["method"] == "residual").to_numpy()
ssw = flag_unusable(ssw, ["F_m_N", "ssw_N"], "SSW rows (residual)", where=fitted)
table = ssw_fit_table(ssw)
log.info("%d fits", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
