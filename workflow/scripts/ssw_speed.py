"""The SSW tracks of every chain in one table, and their speeds against Eq. 5
(chain.analysis.ssw_speed.ssw_speed_table)."""

import pandas as pd
from _logging import done, start

from chain.analysis.ssw_speed import ssw_speed_table
from chain.atomic import write_csv_atomic
from chain.physics.materials import get_material
from chain.physics.theory import nesterenko_speed_from_force

log = start(snakemake)
material = get_material(snakemake.params.material)
radius = snakemake.params.radius_m
track = pd.concat([pd.read_csv(path) for path in snakemake.input.tracks], ignore_index=True)
speed = ssw_speed_table(
    track, lambda force: nesterenko_speed_from_force(force, material, radius), 2 * radius
)
log.info("%d speed rows", len(speed))
write_csv_atomic(track, snakemake.output.track)
write_csv_atomic(speed, snakemake.output.speed)
done(snakemake)
