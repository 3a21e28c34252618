"""summary.md: the side-by-side table, written from summary.json (chain.report.text.markdown)."""

import _hand_off  # noqa: F401 (first: the job may run in the job server)
from _logging import start

from chain.report.text.markdown import write_summary_markdown

log = start(snakemake)
write_summary_markdown(snakemake.input.json, snakemake.output.md)
log.info("done")
