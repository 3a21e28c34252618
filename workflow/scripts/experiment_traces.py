"""Every experiment dataset (measured-trace format) as a trace table (chain.apparatus.measured)."""

from _inputs import dataset_folders
from _logging import done, start

from chain.apparatus.measured import load_dataset
from chain.traces import write_traces

log = start(snakemake)
p = snakemake.params
for dataset, folder, traces in zip(p.datasets, dataset_folders(snakemake), snakemake.output):
    table = load_dataset(
        folder, name=dataset["name"], bad_channels=p.bad_channels, cache_dir=p.cache
    )
    if set(table["N"]) != {dataset["N"]}:
        raise ValueError(f"{folder}: N = {sorted(set(table['N']))}, expected {dataset['N']}")
    shots = table.drop_duplicates("shot")
    counts = [int((shots["kind"] == kind).sum()) for kind in ("collision", "reference")]
    log.info(
        "%s -> %s: %d collision and %d reference shots, %d amplitudes",
        *(folder, traces, *counts, shots["amplitude"].nunique()),
    )
    write_traces(table, traces)  # atomic: temporary file, then rename
done(snakemake)
