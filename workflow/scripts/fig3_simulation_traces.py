"""Fig. 3: simulated forces at the sensor beads (chain.report.figures.fig3_simulation_traces)."""

import pandas as pd
from _logging import done, start

from chain.report.figures.fig3_simulation_traces import fig3_simulation_traces
from chain.report.figures.style import save_figure
from chain.traces import read_traces

log = start(snakemake)
p = snakemake.params
# Trace files of this run: write_traces checked them in the job that wrote them.
fig = fig3_simulation_traces(
    [read_traces(path, check=False) for path in snakemake.input.traces],
    pd.read_csv(snakemake.input.pulses),
    pd.read_csv(snakemake.input.ssw),
    model=p.model,
    representative_force_N=p.representative_force_N,
    representative_index=p.representative_index,
    estimator=p.estimator,
    label=p.label,
)
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
