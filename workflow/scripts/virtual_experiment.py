"""The virtual experiment on one chain (chain.apparatus.virtual.run_virtual_experiment): a
model of the apparatus writing a dataset in the measured-trace format (not data)."""

from _logging import done, start

from chain.apparatus.virtual import VirtualExperiment, run_virtual_experiment

log = start(snakemake)
# The chain's settings (RunPlan.virtual_settings): the fields under the config's names.
settings = VirtualExperiment(**snakemake.params.settings)
speeds = settings.nominal_speeds
log.info(
    "N = %d, sensors %s, %d amplitudes (%.3g..%.3g m/s), %d collision + %d reference shots "
    "each, seed %d",
    *(settings.n_beads, list(settings.sensor_beads), len(speeds), speeds.min(), speeds.max()),
    *(settings.collision_shots, settings.reference_shots, settings.seed),
)
# Written to a temporary folder that then replaces the output folder: all or nothing.
run_virtual_experiment(settings, snakemake.output[0], snakemake.params.dataset)
done(snakemake)
