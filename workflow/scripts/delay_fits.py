"""The crossing delay of every collision shot (chain.analysis.delays.delay_table), and
the fits of |Delta| = C F_m^(-1/6) and of a free power law (chain.analysis.recipe)."""

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.analysis.delays import delay_table
from chain.analysis.recipe import fit_delays
from chain.atomic import write_csv_atomic

log = start(snakemake)
delays = delay_table(pd.read_csv(snakemake.input.pulses), selection=selection(snakemake))
log.info("%d delay rows", len(delays))
write_csv_atomic(delays, snakemake.output.delays)
# The fits read the table as written (its 10 significant digits), as every reader does.
fits = fit_delays(pd.read_csv(snakemake.output.delays))
log.info("%d fits", len(fits))
write_csv_atomic(fits, snakemake.output.fits)
done(snakemake)
