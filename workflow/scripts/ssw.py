"""Secondary solitary waves behind every crossed pulse (chain.analysis.ssw.ssw_table)."""

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.analysis.ssw import ssw_table
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
write_csv_atomic(pd.concat(tables, ignore_index=True), snakemake.output[0])
done(snakemake)
