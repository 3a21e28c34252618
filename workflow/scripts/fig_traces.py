"""Fig. 2 (experiment) or Fig. 3 (simulation): forces at the sensor beads."""

from pathlib import Path

import pandas as pd
from _inputs import selection
from _logging import start

from chain.report.figures import fig2_experiment_traces, fig3_simulation_traces, save_figure
from chain.traces import read_traces

log = start(snakemake)
p = snakemake.params
if snakemake.rule.startswith("fig3"):
    draw, extra = fig3_simulation_traces, {}
else:  # Fig. 2 shows a collision shot that the acceptance protocol kept
    draw, extra = fig2_experiment_traces, {"selection": selection(snakemake)}
fig = draw(
    [read_traces(path) for path in snakemake.input.traces],
    pd.read_csv(snakemake.input.pulses),
    pd.read_csv(snakemake.input.ssw),
    model=p.model,
    representative_force_N=p.representative_force_N,
    representative_index=p.representative_index,
    estimator=p.estimator,
    label=p.label,
    **extra,
)
save_figure(fig, Path(snakemake.output.pdf).with_suffix(""))
log.info("done")
