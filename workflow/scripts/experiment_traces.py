"""One experiment dataset (measured-trace format) as a trace table (chain.measured)."""

from _logging import start

from chain.measured import load_dataset
from chain.traces import write_traces

log = start(snakemake)
name, n_beads = snakemake.wildcards.dataset, int(snakemake.wildcards.N)
table = load_dataset(snakemake.params.folder, name=name)
if set(table["N"]) != {n_beads}:
    raise ValueError(
        f"{snakemake.params.folder}: N = {sorted(set(table['N']))}, expected {n_beads}"
    )
shots = table.drop_duplicates("shot")
log.info(
    "%s: %d collision and %d reference shots, %d amplitudes",
    snakemake.params.folder,
    int((shots["kind"] == "collision").sum()),
    int((shots["kind"] == "reference").sum()),
    shots["amplitude"].nunique(),
)
write_traces(table, snakemake.output[0])  # atomic: temporary file, then rename
log.info("done")
