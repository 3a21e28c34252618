"""Figure ssw_spacetime: the SSW along the chain (chain.report.fig_ssw_spacetime)."""

from pathlib import Path

import pandas as pd
from _logging import start

from chain.report.fig_ssw_spacetime import fig_ssw_spacetime
from chain.report.style import save_figure

log = start(snakemake)
fields = {}
for path in snakemake.input.fields:
    field = pd.read_csv(path)
    fields[int(Path(path).name.split("_N")[1].split("_")[0])] = field
fig = fig_ssw_spacetime(fields, pd.read_csv(snakemake.input.track), snakemake.params.model)
save_figure(fig, Path(snakemake.output.pdf).with_suffix(""))
log.info("done")
