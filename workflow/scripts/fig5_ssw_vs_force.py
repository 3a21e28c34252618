"""Fig. 5: SSW amplitude against incident amplitude at the sensors, and SSW / F_m along
the chain (chain.report.figures.fig5_ssw_vs_force)."""

from pathlib import Path

import pandas as pd
from _logging import start

from chain.analysis.ssw_track import sensor_distance
from chain.report.figures.fig5_ssw_vs_force import fig5_ssw_vs_force
from chain.report.figures.style import save_figure

log = start(snakemake)
fig = fig5_ssw_vs_force(
    pd.read_csv(snakemake.input.ssw),
    pd.read_csv(snakemake.input.fits),
    pd.read_csv(snakemake.input.track),
    pd.read_csv(snakemake.input.speed),
    sensor_distances={
        int(n): sensor_distance(int(n), sensors) for n, sensors in snakemake.params.sensors.items()
    },
    experiment_label=snakemake.params.experiment_label,
)
save_figure(fig, Path(snakemake.output.pdf).with_suffix(""))
log.info("done")
