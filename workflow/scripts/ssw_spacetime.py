"""Figure ssw_spacetime: the SSW along the chain (chain.report.figures.fig_ssw_spacetime)."""

import pandas as pd
from _logging import done, start

from chain.report.figures.fig_ssw_spacetime import fig_ssw_spacetime
from chain.report.figures.style import save_figure

log = start(snakemake)
p, i = snakemake.params, snakemake.input
# One field file per chain, in the order of params.chains (long_chains: of long_fields).
fields = {int(n): pd.read_csv(f) for n, f in zip(p.chains, i.fields, strict=True)}
long_fields = {int(n): pd.read_csv(f) for n, f in zip(p.long_chains, i.long_fields, strict=True)}
fig = fig_ssw_spacetime(fields, pd.read_csv(i.track), p.model, long_fields)
# The PNG drawn in a forked process beside the PDF, whatever the threads of the job (a
# local run schedules it on one core, profiles/default); the fork lives for the save.
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"), processes=2)
done(snakemake)
