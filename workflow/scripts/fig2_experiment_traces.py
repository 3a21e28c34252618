"""Fig. 2: experiment forces at the sensor beads, a shot the acceptance protocol kept
(chain.report.figures.fig2_experiment_traces)."""

import pandas as pd
from _inputs import selection
from _logging import done, start

from chain.report.figures.fig2_experiment_traces import fig2_experiment_traces
from chain.report.figures.style import save_figure
from chain.traces import read_traces

log = start(snakemake)
p = snakemake.params
# Trace files of this run: write_traces checked them in the job that wrote them.
fig = fig2_experiment_traces(
    [read_traces(path, check=False) for path in snakemake.input.traces],
    pd.read_csv(snakemake.input.pulses),
    pd.read_csv(snakemake.input.ssw),
    representative_force_N=p.representative_force_N,
    estimator=p.estimator,
    label=p.label,
    selection=selection(snakemake),
)
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
