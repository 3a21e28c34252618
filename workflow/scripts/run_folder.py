"""The run folder: plain copies of what the run shows, checked against the digests
stored with them, the jobs' logs and benchmarks, and SHA256SUMS
(chain.pipeline.run.publish)."""

from _logging import start

from chain.pipeline.run.publish import fill_run_folder

log = start(snakemake, check_inputs=False)
targets = [path for path in snakemake.output if path != snakemake.output.sums]
for line in fill_run_folder(list(snakemake.input), targets, snakemake.output.sums):
    log.info(line)
