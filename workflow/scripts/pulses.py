"""Fit the pulses of every trace file (chain.analysis.pulse_rows.pulse_table)."""

import pandas as pd
from _logging import done, start

from chain.analysis.pulse_rows import pulse_table
from chain.atomic import write_csv_atomic
from chain.traces import read_traces

log = start(snakemake)
estimators = tuple(snakemake.params.estimators)
tables = []
# Trace files of this run: write_traces checked them in the job that wrote them.
for path in snakemake.input.traces:
    table = pulse_table(read_traces(path, check=False), estimators=estimators)
    log.info("%s: %d pulse rows, %d not ok", path, len(table), int((~table["ok"]).sum()))
    tables.append(table)
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output[0])
done(snakemake)
