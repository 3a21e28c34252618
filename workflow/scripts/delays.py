"""Crossing delay of every collision shot (chain.analysis.delays.delay_table)."""

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.analysis.delays import delay_table
from chain.atomic import write_csv_atomic

log = start(snakemake)
table = delay_table(pd.read_csv(snakemake.input.pulses), selection=selection(snakemake))
log.info("%d delay rows", len(table))
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
