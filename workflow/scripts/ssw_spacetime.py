"""Figure ssw_spacetime: the SSW along the chain (chain.report.figures.fig_ssw_spacetime),
the collision whose incident amplitude is closest to the figures' representative force
(or the amplitude index given) on each chain."""

import pandas as pd
from _logging import done, start

from chain.analysis.ssw_track import Field, representative_shot
from chain.report.figures.fig_ssw_spacetime import fig_ssw_spacetime
from chain.report.figures.style import save_figure

log = start(snakemake)
p, i = snakemake.params, snakemake.input
track = pd.read_csv(i.track)


def shown(chains, files):
    """N -> (its pooled field, the shot shown), one field file per chain, in order."""
    fields = {}
    for n, path in zip(chains, files, strict=True):
        rows = track[(track["model"] == p.model) & (track["N"] == int(n))]
        shot = representative_shot(rows, p.representative_force_N, p.representative_index)
        fields[int(n)] = (Field.load(path), shot)
    return fields


fig = fig_ssw_spacetime(
    shown(p.chains, i.fields), track, p.model, shown(p.long_chains, i.long_fields)
)
# The PNG drawn in a forked process beside the PDF, whatever the threads of the job (a
# local run schedules it on one core, profiles/default); the fork lives for the save.
save_figure(fig, snakemake.output.pdf.removesuffix(".pdf"), processes=2)
done(snakemake)
