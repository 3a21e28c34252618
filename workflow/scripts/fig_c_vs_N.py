"""Sweep figure: C against N, odd and even (chain.report.figures.fig_c_vs_N.fig_c_vs_N)."""

import pandas as pd
from _logging import done, start

from chain.report.figures.fig_c_vs_N import fig_c_vs_N
from chain.report.figures.style import save_figure

log = start(snakemake)
fig = fig_c_vs_N(pd.read_csv(snakemake.input.sweep))
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
