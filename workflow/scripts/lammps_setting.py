"""One friction/rotation setting on one chain, run by LAMMPS and analysed
(chain.studies.lammps_sweep.run_sweep_setting), with every estimator of the run."""

from _logging import done, start

from chain.atomic import write_csv_atomic
from chain.studies.lammps_sweep import run_sweep_setting
from chain.traces import write_traces

log = start(snakemake)
w, p = snakemake.wildcards, snakemake.params
out = run_sweep_setting(p.config, int(w.N), p.sensors, w.setting, p.estimators)
write_traces(out["traces"], snakemake.output.traces)
for name in ("runs", "delay_fits", "ssw_fits"):
    write_csv_atomic(out[name], snakemake.output[name])
spin, slopes = out["runs"]["max_spin_rad_s"].max(), out["ssw_fits"]["slope"].tolist()
log.info("%s N = %s: largest bead spin %.3g rad/s; SSW slopes %s", w.setting, w.N, spin, slopes)
done(snakemake)
