"""summary.json: the run's numbers beside the paper's (chain.report.numbers.summary),
with the sections the studies add (each part's function of its tables, as its rule file
names it: params.parts); and summary.md, its side-by-side table
(chain.report.text.markdown), written from the file."""

import importlib

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.report.numbers.claims import with_claims
from chain.report.numbers.summary import build_summary, write_summary_json
from chain.report.text.markdown import write_summary_markdown

log = start(snakemake)
p, i = snakemake.params, snakemake.input
delay_fits, delays, ssw = (pd.read_csv(path) for path in (i.delay_fits, i.delays, i.ssw))
summary = build_summary(
    run_name=p.run_name,
    material=p.material,
    radius_m=p.radius_m,
    delay_fits=delay_fits,
    ssw_fits=pd.read_csv(i.ssw_fits),
    runs=pd.concat([pd.read_csv(path) for path in i.runs], ignore_index=True),
    conservative_models=p.conservative_models,
    main_estimator=p.estimator,
    experiment_label=p.experiment_label,
    pulses=pd.read_csv(i.pulses),
    delays=delays,
    ssw=ssw,
    selection=selection(snakemake),
    tolerance=p.tolerance if i.get("selection") else None,
    ssw_speed=pd.read_csv(i.ssw_speed),
)
# The studies' sections (the ablation verdict, the spread of C, the mechanisms'...).
run = {"delay_fits": delay_fits, "estimator": p.estimator}
for part, (function, names) in p.parts.items():
    module, name = function.split(":")
    tables = {table: pd.read_csv(i[f"{part}__{table}"]) for table in names}
    summary[part] = getattr(importlib.import_module(module), name)(tables, run)
# The studies switched off by the config (key absent when all ran).
if p.studies_not_run:
    summary["studies_not_run"] = list(p.studies_not_run)
# The claim table last: its "why not" quotes the studies above.
summary = with_claims(summary, delays, ssw)
summary["provenance"] = p.provenance  # versions, and the lock's
write_summary_json(summary, snakemake.output.json)
log.info("max energy drift of conservative runs: %s", summary["max_energy_drift"])
log.info("flagged rows: %s", summary["flagged"])
log.info("selection: %s", summary["selection"])
write_summary_markdown(snakemake.output.json, snakemake.output.md)
done(snakemake)
