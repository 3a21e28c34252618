"""Re-simulate one chain's collisions with every contact recorded and track the SSW
(chain.analysis.ssw_track). The field Fig. ssw_spacetime shows: ssw_fields.py."""

from _logging import done, start

from chain.analysis.ssw_track import ssw_track_table
from chain.apparatus.shots import shot_time_step
from chain.atomic import write_csv_atomic
from chain.physics.simulation import simulate
from chain.pipeline.plan.jobs import chain_of

log = start(snakemake)
job = snakemake.params.job
model = chain_of(job)
# The collision shots of the simulate rule (same step, duration and sampling), with
# every contact force kept instead of two sensor readings.
speeds = job["speeds_m_s"]
dt = shot_time_step(model, speeds, job["time_step_s"], job["record_interval_s"])
result = simulate(
    model,
    speeds,
    speeds,
    duration=job["duration_s"],
    dt=dt,
    record_interval=job["record_interval_s"],
    max_energy_drift=job["max_energy_drift"],
    contacts="all",  # the track follows the wave contact by contact, whatever N
    beads=(),
)
track = ssw_track_table(result.time, result.contact_force, source="simulation", model=job["model"])
log.info("%d of %d contacts separated", track["separated"].sum(), len(track))
write_csv_atomic(track, snakemake.output.track)
done(snakemake)
