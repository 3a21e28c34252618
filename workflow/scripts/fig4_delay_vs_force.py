"""Fig. 4: |Delta| against F_m (chain.report.figures.fig4_delay_vs_force)."""

import pandas as pd
from _logging import done, start

from chain.physics.theory import ballistic_constants
from chain.report.figures.fig4_delay_vs_force import fig4_delay_vs_force
from chain.report.figures.style import save_figure

log = start(snakemake)
p = snakemake.params
delays, fits = pd.read_csv(snakemake.input.delays), pd.read_csv(snakemake.input.fits)
constants = ballistic_constants(p.material, p.radius_m)
fig = fig4_delay_vs_force(
    delays, fits, constants=constants, estimator=p.estimator, experiment_label=p.experiment_label
)
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
