"""The paper's acceptance protocol on the experiment shots (chain.analysis.selection)."""

import pandas as pd
from _logging import start

from chain.analysis.selection import select_shots
from chain.atomic import write_csv_atomic

log = start(snakemake)
p = snakemake.params
pulses = pd.read_csv(snakemake.input.pulses)
pulses = pulses[pulses["source"] == "experiment"]
# Every recorded shot, so that one without any pulse row is listed as rejected.
columns = ["source", "model", "N", "shot", "kind", "amplitude"]
shots = pd.concat(
    [pd.read_csv(path, usecols=columns).drop_duplicates() for path in snakemake.input.traces],
    ignore_index=True,
)
table = select_shots(pulses, p.tolerance, estimator=p.estimator, shots=shots)
for (model, n, kind), group in table.groupby(["model", "N", "kind"]):
    log.info(
        "%s N = %s %s: %d kept, %d rejected",
        model,
        n,
        kind,
        group["kept"].sum(),
        (~group["kept"]).sum(),
    )
for row in table[~table["kept"]].itertuples():
    log.info("rejected %s N = %s shot %s: %s", row.model, row.N, row.shot, row.reason)
write_csv_atomic(table, snakemake.output[0])
