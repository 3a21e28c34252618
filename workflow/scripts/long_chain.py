"""The collisions of one long chain (no sensors) for every launch speed, every contact
recorded: the SSW tracked along the chain (chain.analysis.ssw_track), and the field
pooled for the space-time figure."""

from _logging import done, start

from chain.analysis.ssw_track import pooled_field, ssw_track_table
from chain.apparatus.shots import shot_time_step
from chain.atomic import write_csv_atomic
from chain.physics.simulation import simulate
from chain.pipeline.plan.jobs import chain_of

log = start(snakemake)
job = snakemake.params.job
model, speeds = chain_of(job), job["speeds_m_s"]
result = simulate(
    model,
    speeds,
    speeds,
    duration=job["duration_s"],
    dt=shot_time_step(model, speeds, job["time_step_s"], job["record_interval_s"]),
    record_interval=job["record_interval_s"],
    max_energy_drift=job["max_energy_drift"],
    contacts="all",  # the track follows the wave contact by contact, whatever N
    beads=(),
)
track = ssw_track_table(result.time, result.contact_force, source="simulation", model=job["model"])
log.info("%d of %d contacts separated", track["separated"].sum(), len(track))
write_csv_atomic(track, snakemake.output.track)
pooled_field(result.time, result.contact_force).save(snakemake.output.field)
done(snakemake)
