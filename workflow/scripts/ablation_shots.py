"""The shots of every ablation variant the run makes, in memory (chain.studies.ablation:
each distinct launch integrated once, the run's own shots read from its datasets),
kept as trace tables for the analysis (chain.traces.save_trace_sets)."""

from _logging import done, start

from chain.studies.ablation_shots import variant_shots
from chain.traces import save_trace_sets

log = start(snakemake)
p = snakemake.params
shots = variant_shots(p.variants, p.run, list(snakemake.input.datasets), p.series)
log.info("%d shot sets for %d variants", len(shots), len(p.variants))
save_trace_sets(shots, snakemake.output.shots)
done(snakemake)
