"""Re-simulate one chain's collisions with every contact recorded and track the SSW
(chain.analysis.ssw_track); write the track and the field of the shot Fig. ssw_spacetime shows."""

from _logging import start

from chain.analysis.ssw_track import field_table, representative_shot, ssw_track_table
from chain.apparatus.shots import shot_time_step
from chain.atomic import write_csv_atomic
from chain.physics.materials import get_material
from chain.physics.model import uniform_chain
from chain.physics.simulation import simulate

log = start(snakemake)
p = snakemake.params
sim = p.simulation
model = uniform_chain(
    int(snakemake.wildcards.N),
    get_material(p.material),
    p.radius_m,
    p.eta_s,
    sensor_beads=p.sensors if sim["readout"] == "sensor" else (),
)
# The collision shots of the simulate rule (same step, duration and sampling), with
# every contact force kept instead of two sensor readings.
dt = shot_time_step(model, p.speeds_m_s, sim["time_step_s"], sim["record_interval_s"])
result = simulate(
    model,
    p.speeds_m_s,
    p.speeds_m_s,
    duration=p.duration_s,
    dt=dt,
    record_interval=sim["record_interval_s"],
    max_energy_drift=sim["max_energy_drift"],
)
track = ssw_track_table(
    result.time, result.contact_force, source="simulation", model=snakemake.wildcards.model
)
log.info("%d of %d contacts separated", track["separated"].sum(), len(track))
shot = representative_shot(track, p.representative_force_N, p.representative_index)
write_csv_atomic(track, snakemake.output.track)
write_csv_atomic(
    field_table(result.time, result.contact_force[shot], shot=shot), snakemake.output.field
)
log.info("field of shot %d written", shot)
