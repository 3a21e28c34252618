"""Fig. 1, the setup, drawn from the configured chains (chain.report.figures.fig1_setup)."""

from _logging import done, start

from chain.report.figures.fig1_setup import fig1_setup
from chain.report.figures.style import save_figure

log = start(snakemake)
p = snakemake.params
fig = fig1_setup(
    p.chains, bead_radius_m=p.radius_m, striker_radius_m=p.striker_radius_m, material=p.material
)
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"))
done(snakemake)
