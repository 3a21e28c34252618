"""Figure ssw_spacetime: the SSW along the chain (chain.report.figures.fig_ssw_spacetime)."""

from pathlib import Path

import pandas as pd
from _logging import start

from chain.report.figures.fig_ssw_spacetime import fig_ssw_spacetime
from chain.report.figures.style import save_figure

log = start(snakemake)
# One field file per chain, in the order of params.chains (long_chains: of long_fields).
fields = {
    int(n): pd.read_csv(path)
    for n, path in zip(snakemake.params.chains, snakemake.input.fields, strict=True)
}
long_fields = {
    int(n): pd.read_csv(path)
    for n, path in zip(snakemake.params.long_chains, snakemake.input.long_fields, strict=True)
}
fig = fig_ssw_spacetime(
    fields, pd.read_csv(snakemake.input.track), snakemake.params.model, long_fields
)
# The PNG drawn in a forked process beside the PDF, whatever the threads Snakemake
# scheduled the job with: a local run schedules it on one core so that it does not
# wait for two free ones (profiles/default); the fork lives for the save (~5 s).
save_figure(fig, Path(snakemake.output.pdf).with_suffix(""), processes=2)
log.info("done")
