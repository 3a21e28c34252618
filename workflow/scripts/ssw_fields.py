"""Re-simulate the collision Fig. ssw_spacetime shows on each of its chains, every
contact recorded, and write its field (chain.analysis.ssw_track.field_table): that shot
only, at the time step of ssw_track's whole batch (the same numbers bit for bit), so
that a figure key recomputes milliseconds of integration, not the tracks."""

import pandas as pd
from _logging import done, start

from chain.analysis.ssw_track import field_table, representative_shot
from chain.apparatus.shots import shot_time_step
from chain.atomic import write_csv_atomic
from chain.physics.simulation import simulate
from chain.pipeline.plan.jobs import chain_of

log = start(snakemake)
p = snakemake.params
for job, track_file, field_file in zip(p.jobs, snakemake.input.tracks, snakemake.output):
    model = chain_of(job)
    speeds = job["speeds_m_s"]
    shot = representative_shot(
        pd.read_csv(track_file), p.representative_force_N, p.representative_index
    )
    result = simulate(
        model,
        [speeds[shot]],
        [speeds[shot]],
        duration=job["duration_s"],
        dt=shot_time_step(model, speeds, job["time_step_s"], job["record_interval_s"]),
        record_interval=job["record_interval_s"],
        max_energy_drift=job["max_energy_drift"],
        contacts="all",
        beads=(),
    )
    write_csv_atomic(field_table(result.time, result.contact_force[0], shot=shot), field_file)
    log.info("%s N = %d: field of shot %d written", job["model"], job["N"], shot)
done(snakemake)
