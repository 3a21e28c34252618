"""Fig. 5: SSW amplitude against incident amplitude at the sensors, and SSW / F_m along
the chain (chain.report.figures.fig5_ssw_vs_force)."""

import pandas as pd
from _logging import done, start

from chain.analysis.ssw_track import sensor_distance
from chain.report.figures.fig5_ssw_vs_force import fig5_ssw_vs_force
from chain.report.figures.style import save_figure

log = start(snakemake)
p, i = snakemake.params, snakemake.input
fig = fig5_ssw_vs_force(
    *(pd.read_csv(path) for path in (i.ssw, i.fits, i.track, i.speed)),
    sensor_distances={int(n): sensor_distance(int(n), s) for n, s in p.sensors.items()},
    experiment_label=p.experiment_label,
)
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
