"""Secondary solitary waves behind every crossed pulse (chain.analysis.ssw.ssw_table),
and the fits of SSW amplitude = slope x F_m (chain.analysis.ssw_fits.ssw_fit_table)."""

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.analysis.rows import flag_unusable
from chain.analysis.ssw import ssw_table
from chain.analysis.ssw_fits import ssw_fit_table
from chain.atomic import write_csv_atomic
from chain.traces import read_traces

log = start(snakemake)
pulses = pd.read_csv(snakemake.input.pulses)
shots, estimator = selection(snakemake), snakemake.params.estimator
tables = []
# Trace files of this run: write_traces checked them in the job that wrote them.
for path in snakemake.input.traces:
    table = ssw_table(read_traces(path, check=False), pulses, selection=shots, estimator=estimator)
    log.info("%s: %d SSW rows", path, len(table))
    tables.append(table)
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output.ssw)
# The fits read the table as written (its 10 significant digits), as every reader does;
# the fitted rows (method residual) flagged (ok False) or NaN stay out, counted.
ssw = pd.read_csv(snakemake.output.ssw)
fitted = (ssw["method"] == "residual").to_numpy()
ssw = flag_unusable(ssw, ["F_m_N", "ssw_N"], "SSW rows (residual)", where=fitted)
fits = ssw_fit_table(ssw)
log.info("%d fits", len(fits))
write_csv_atomic(fits, snakemake.output.fits)
done(snakemake)
