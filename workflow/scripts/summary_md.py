"""summary.md: the side-by-side table, written from summary.json (chain.report.summary_md)."""

from _logging import start

from chain.report.summary_md import write_summary_markdown

log = start(snakemake)
write_summary_markdown(snakemake.input.json, snakemake.output.md)
log.info("done")
