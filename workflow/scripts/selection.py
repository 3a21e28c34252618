"""The paper's acceptance protocol on the experiment shots (chain.analysis.selection)."""

import pandas as pd
from _inputs import dataset_folders
from _logging import done, start

from chain.analysis.selection import select_shots
from chain.apparatus.dataset_check import check_dataset
from chain.atomic import write_csv_atomic
from chain.pipeline.plan.datasets import skipped_shot_rows

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
if p.bad_channels == "skip":
    # Shots left out of the traces for a dead or saturated channel: rejected, with why.
    skipped = [
        skipped_shot_rows(check_dataset(folder, cache_dir=p.cache), d["name"])
        for d, folder in zip(p.datasets, dataset_folders(snakemake))
    ]
    table = pd.concat([table, *skipped], ignore_index=True)
    table = table.sort_values(["source", "model", "N", "shot"], kind="stable")
for (model, n, kind), kept in table.groupby(["model", "N", "kind"])["kept"]:
    log.info("%s N = %s %s: %d kept, %d rejected", model, n, kind, kept.sum(), (~kept).sum())
for row in table[~table["kept"]].itertuples():
    log.info("rejected %s N = %s shot %s: %s", row.model, row.N, row.shot, row.reason)
write_csv_atomic(table, snakemake.output[0])
done(snakemake)
