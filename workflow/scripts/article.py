"""article.pdf: the reproduction as an article (chain.report.text.article + article.typ)."""

import json

from _logging import done, start

from chain.report.text.article import article_numbers, compile_article

log = start(snakemake)
with open(snakemake.input.summary, encoding="utf-8") as stream:
    summary = json.load(stream)
p = snakemake.params
numbers = article_numbers(summary, setup=p.setup, provenance=p.provenance)
compile_article(snakemake.input.source, numbers, snakemake.input.figures, snakemake.output[0])
log.info("claims: %s", [(c["claim"], c["agrees"]) for c in numbers["claims"]])
done(snakemake)
