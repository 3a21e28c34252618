"""Simulate one model on one chain for every launch speed (chain.apparatus.shots), every
contact recorded: the sensor traces, the runs, the SSW tracked along the chain
(chain.analysis.ssw_track), the collisions' field pooled for the space-time figure, and
every bead's felt force (what the C-sensitivity study reads at its shifted sensors)."""

from _logging import done, start

from chain.analysis.ssw_track import pooled_field, ssw_track_table
from chain.apparatus.readings import save_readings
from chain.apparatus.shots import shot_tables, simulate_launches
from chain.atomic import write_csv_atomic
from chain.pipeline.plan.jobs import chain_of, simulation_kwargs
from chain.traces import write_traces

log = start(snakemake)
job, out = snakemake.params.job, snakemake.output
log.info("N = %d, eta = %g s, %d launch speeds", job["N"], job["eta_s"], len(job["speeds_m_s"]))
launches = simulate_launches(chain_of(job), job["speeds_m_s"], **simulation_kwargs(job))
name = job["model"]
traces, runs = shot_tables(launches, job["sensors"], model_name=name, readout=job["readout"])
log.info("dt = %g s, largest energy drift %.3g", runs["dt_s"].iloc[0], runs["energy_drift"].max())
write_traces(traces, out.traces)
write_csv_atomic(runs, out.runs)
collisions = launches[0]
track = ssw_track_table(collisions.time, collisions.contact_force, source="simulation", model=name)
log.info("%d of %d contacts separated", track["separated"].sum(), len(track))
write_csv_atomic(track, out.track)
pooled_field(collisions.time, collisions.contact_force).save(out.field)
save_readings(launches, out.readings)
done(snakemake)
