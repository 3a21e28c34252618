"""Fig. 5: SSW amplitude against incident amplitude (chain.report.fig5_ssw_vs_force)."""

from pathlib import Path

import pandas as pd
from _logging import start

from chain.report.fig5_ssw_vs_force import fig5_ssw_vs_force
from chain.report.style import save_figure

log = start(snakemake)
fig = fig5_ssw_vs_force(
    pd.read_csv(snakemake.input.ssw),
    pd.read_csv(snakemake.input.fits),
    experiment_label=snakemake.params.experiment_label,
)
save_figure(fig, Path(snakemake.output.pdf).with_suffix(""))
log.info("done")
