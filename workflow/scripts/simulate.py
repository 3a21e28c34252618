"""Simulate one model on one chain for every launch speed (chain.apparatus.shots)."""

from _logging import start

from chain.apparatus.shots import simulate_shots
from chain.atomic import write_csv_atomic
from chain.physics.materials import get_material
from chain.physics.model import uniform_chain
from chain.traces import write_traces

log = start(snakemake)
p = snakemake.params
sim = p.simulation
n_beads = int(snakemake.wildcards.N)
model = uniform_chain(
    n_beads,
    get_material(p.material),
    p.radius_m,
    p.eta_s,
    sensor_beads=p.sensors if sim["readout"] == "sensor" else (),
)
log.info("N = %d, eta = %g s, %d launch speeds", n_beads, p.eta_s, len(p.speeds_m_s))
traces, runs = simulate_shots(
    model,
    p.speeds_m_s,
    p.sensors,
    model_name=snakemake.wildcards.model,
    duration=sim["duration_s"],
    dt=sim["time_step_s"],
    record_interval=sim["record_interval_s"],
    readout=sim["readout"],
    max_energy_drift=sim["max_energy_drift"],
)
log.info("dt = %g s, largest energy drift %.3g", runs["dt_s"].iloc[0], runs["energy_drift"].max())
write_traces(traces, snakemake.output.traces)
write_csv_atomic(runs, snakemake.output.runs)
log.info("done")
