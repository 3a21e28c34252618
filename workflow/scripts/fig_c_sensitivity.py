"""Supplementary figure: C against our choices (chain.report.figures.fig_c_sensitivity)."""

import pandas as pd
from _logging import done, start

from chain.report.figures.fig_c_sensitivity import fig_c_sensitivity
from chain.report.figures.style import save_figure

log = start(snakemake)
fig = fig_c_sensitivity(pd.read_csv(snakemake.input.table))
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
