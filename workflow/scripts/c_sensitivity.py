"""tables/c_sensitivity.csv: C and the free exponent per choice of estimator, eta,
sensor pair and amplitude range (chain.studies.c_sensitivity), on simulated shots."""

from _logging import start

from chain.apparatus.shots import simulate_shots
from chain.atomic import write_csv_atomic
from chain.physics.materials import get_material
from chain.physics.model import uniform_chain
from chain.studies.c_sensitivity import c_sensitivity_table, shifted_pairs

log = start(snakemake)
p = snakemake.params
plan, sim = p.plan, p.plan["simulation"]
chains = {int(n): pair for n, pair in plan["chains"].items()}
traces = {}
for eta in plan["eta_s"]:
    traces[eta] = {}
    for n in chains:
        beads = sorted({b for s in [0, *plan["shifts"]] for b in shifted_pairs(chains, s)[n]})
        model = uniform_chain(
            n,
            get_material(p.material),
            p.radius_m,
            eta,
            sensor_beads=beads if sim["readout"] == "sensor" else (),
        )
        traces[eta][n], runs = simulate_shots(
            model,
            plan["speeds_m_s"],
            beads,
            model_name=f"eta{eta * 1e6:.3g}us",
            duration=sim["duration_s"],
            dt=sim["time_step_s"],
            record_interval=sim["record_interval_s"],
            readout=sim["readout"],
            max_energy_drift=sim["max_energy_drift"],
        )
        log.info("eta = %g s, N = %d, beads %s simulated", eta, n, beads)
table = c_sensitivity_table(traces, plan)
for row in table[table["N"].astype(str) == "pooled"].itertuples():
    log.info(
        "%s = %s: C = %.2f +- %.2f, p = %.4f",
        row.choice,
        row.value,
        row.C,
        row.C_stderr,
        row.exponent,
    )
write_csv_atomic(table, snakemake.output[0])
