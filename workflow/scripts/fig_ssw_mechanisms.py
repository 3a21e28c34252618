"""The mechanism figure: SSW/F_m at S2 per mechanism and setting
(chain.report.figures.fig_ssw_mechanisms)."""

import pandas as pd
from _logging import done, start

from chain.report.figures.fig_ssw_mechanisms import fig_ssw_mechanisms
from chain.report.figures.style import save_figure

log = start(snakemake)
fig = fig_ssw_mechanisms(pd.read_csv(snakemake.input.table))
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
