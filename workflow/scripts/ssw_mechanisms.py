"""tables/ssw_mechanisms.csv: SSW/F_m at S2 and C per mechanism and setting
(chain.pipeline.mechanisms.mechanism_rows)."""

import pandas as pd
from _logging import start

from chain.atomic import write_csv_atomic
from chain.pipeline.mechanisms import FRICTION_MECHANISM, mechanism_rows

log = start(snakemake)
p = snakemake.params
table = mechanism_rows(
    FRICTION_MECHANISM,
    p.labels,
    [pd.read_csv(path) for path in snakemake.input.delay_fits],
    [pd.read_csv(path) for path in snakemake.input.ssw_fits],
    p.reference,
)
log.info("%d rows", len(table))
write_csv_atomic(table, snakemake.output[0])
