"""Every experiment dataset (measured-trace format) as a trace table (chain.apparatus.measured)."""

from _logging import start

from chain.apparatus.measured import load_dataset
from chain.traces import write_traces

log = start(snakemake)
for dataset in snakemake.params.datasets:
    table = load_dataset(
        dataset["folder"],
        name=dataset["name"],
        bad_channels=snakemake.params.bad_channels,
        cache_dir=snakemake.params.cache,
    )
    if set(table["N"]) != {dataset["N"]}:
        raise ValueError(
            f"{dataset['folder']}: N = {sorted(set(table['N']))}, expected {dataset['N']}"
        )
    shots = table.drop_duplicates("shot")
    log.info(
        "%s -> %s: %d collision and %d reference shots, %d amplitudes",
        dataset["folder"],
        dataset["traces"],
        int((shots["kind"] == "collision").sum()),
        int((shots["kind"] == "reference").sum()),
        shots["amplitude"].nunique(),
    )
    write_traces(table, dataset["traces"])  # atomic: temporary file, then rename
log.info("done")
