"""summary.md: the side-by-side table, written from summary.json (chain.report.text.markdown)."""

from _logging import done, start

from chain.report.text.markdown import write_summary_markdown

log = start(snakemake)
write_summary_markdown(snakemake.input.json, snakemake.output.md)
done(snakemake)
