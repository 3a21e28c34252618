"""The mechanism study's part of the plan (models, not data): why are the measured SSW
larger? On the optional LAMMPS engine, the frictionless 1D cross-check against our
kernel (``tables/lammps_check.csv``) and one job per (setting, chain) of the
friction/rotation sweep and of a viscous inter-bead force; beside them the virtual
experiment's candidates (ablation variants with a mechanism). ``tables/ssw_mechanisms.csv``
and its figure gather the default run's settings; the target ``mechanisms`` all of them
(``tables/ssw_mechanisms_all.csv``). Without LAMMPS its rules are left out of the run,
and the console says so before any job."""

from __future__ import annotations

from functools import cached_property

from chain.physics.lammps_library import lammps_available
from chain.pipeline.plan.steps import Part, Step
from chain.studies.mechanism_settings import (
    CANDIDATE_REFERENCE,
    candidate_variants,
    setting_label,
    sweep_settings,
    viscous_settings,
)

#: The config keys the LAMMPS jobs read (chain.studies.lammps_check, lammps_sweep).
LAMMPS_KEYS = ("material", "radius_m", "chains", "models", "lammps")


class MechanismPlan(Part):
    """The lammps_check, lammps_check_table, lammps_setting and ssw_mechanisms steps."""

    @cached_property
    def lammps(self) -> bool:
        """Whether the LAMMPS rules run: ``studies.mechanisms`` is on and LAMMPS imports."""
        return self.plan.study("mechanisms") and lammps_available()

    def sweep(self, full: bool) -> dict[str, tuple[float, float]]:
        """Setting name -> (mu_t, mu_b) of the LAMMPS friction sweep (default run's or all)."""
        return sweep_settings(self.plan.config, full=full)

    def viscous(self, full: bool) -> dict[str, float]:
        """Setting name -> gamma (N s/m) of the viscous inter-bead settings."""
        return viscous_settings(self.plan.config, full=full)

    def candidates(self, full: bool) -> dict[str, tuple[str, str]]:
        """Variant -> (mechanism, setting) of the virtual experiment's candidates (its
        ablation variants with a mechanism); none unless the experiment is virtual and
        ``studies.mechanisms`` on."""
        if not (self.plan.experiment.virtual and self.plan.study("mechanisms")):
            return {}
        return candidate_variants(list(self.plan.ablation.variants.values()), full)

    @property
    def table_made(self) -> bool:
        """Whether tables/ssw_mechanisms.csv (and its figure) is made."""
        return self.lammps or bool(self.candidates(full=False))

    def table(self, full: bool) -> list[str]:
        """``[tables/ssw_mechanisms(_all).csv]`` when the run makes it, else ``[]``."""
        made = full or self.table_made
        return [f"{self.plan.tables}/ssw_mechanisms{'_all' if full else ''}.csv"] if made else []

    def check_table(self) -> list[str]:
        """``[tables/lammps_check.csv]`` when LAMMPS runs, else ``[]``."""
        return [self.plan.analysis.table("lammps_check")] if self.lammps else []

    def _setting_files(self, which: str, what: str) -> list[str]:
        """Per-(setting, chain) outputs of the sweep (``what``; ``viscous_<what>`` for
        the viscous settings): "" the default run's, "_all" all; none without LAMMPS."""
        if not self.lammps:
            return []
        full = which == "_all"
        settings = self.viscous(full) if what.startswith("viscous_") else self.sweep(full)
        what = what.removeprefix("viscous_")
        return [f"{self.plan.out}/lammps/{name}_N{n}_{what}.csv"
                for name in settings for n in self.plan.chains]  # fmt: skip

    def _table_inputs(self, which: str) -> dict:
        kinds = ("delay_fits", "ssw_fits")
        files = {f"lammps_{k}": self._setting_files(which, k) for k in kinds}
        files |= {f"viscous_{k}": self._setting_files(which, f"viscous_{k}") for k in kinds}
        names = self.candidates(full=which == "_all")
        files |= {f"candidate_{k}": [self.plan.ablation.files(n, k) for n in names]
                  for k in ("fits", "ssw_fits")}  # fmt: skip
        return files

    def _table_params(self, which: str) -> dict:
        candidates = self.candidates(full=which == "_all")
        return {
            "labels": {name: setting_label(*pair) for name, pair in self.sweep(True).items()},
            "viscous_labels": {name: f"gamma={gamma:g} N s/m"
                               for name, gamma in self.viscous(True).items()},
            "lammps_reference": next(iter(self.sweep(False))),  # the frictionless setting
            "candidates": {name: list(value) for name, value in candidates.items()},
            "candidate_reference": CANDIDATE_REFERENCE,
            "estimator": self.plan.config["analysis"]["main_estimator"],
        }  # fmt: skip

    def steps(self) -> list[Step]:
        """The LAMMPS steps (with LAMMPS) and ssw_mechanisms."""
        plan, log = self.plan, f"{self.plan.out}/logs"
        lammps = {key: plan.config[key] for key in LAMMPS_KEYS if key in plan.config}
        estimators = plan.config["analysis"]["estimators"]
        check = f"{plan.out}/lammps/check_every_estimator.csv"
        settings = [*self.sweep(True), *self.viscous(True)] if self.lammps else []
        one = [{}] if self.lammps else []
        return [
            Step(
                "lammps_check", {"0": check}, jobs=one, log=f"{log}/lammps/check.log",
                params=lambda w: {"config": lammps, "estimators": estimators},
            ),
            Step(
                "lammps_check_table", {"0": plan.analysis.table("lammps_check")}, jobs=one,
                inputs=lambda w: {"table": check}, script="main_estimator_rows",
                params=lambda w: {"column": "estimator",
                                  "estimator": plan.config["analysis"]["main_estimator"]},
                log=f"{log}/tables/lammps_check.log",
            ),
            Step(
                "lammps_setting",
                {what: f"{plan.out}/lammps/{{setting}}_N{{N}}_{what}.csv"
                 for what in ("traces", "runs", "delay_fits", "ssw_fits")},
                jobs=[{"setting": s, "N": n} for s in settings for n in plan.chains],
                params=lambda w: {"config": lammps, "estimators": estimators,
                                  "sensors": list(plan.chains[int(w["N"])])},
                log=f"{log}/lammps/{{setting}}_N{{N}}.log",
            ),
            Step(
                "ssw_mechanisms", {"0": f"{plan.tables}/ssw_mechanisms{{which}}.csv"},
                jobs=[{"which": w} for w in ("", "_all") if w or self.table_made],
                inputs=lambda w: self._table_inputs(w["which"]),
                params=lambda w: self._table_params(w["which"]),
                log=f"{log}/tables/ssw_mechanisms{{which}}.log",
            ),
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """The default run's tables: lammps_check.csv (with LAMMPS), ssw_mechanisms.csv."""
        return self.check_table() + self.table(full=False)

    def full_targets(self) -> list[str]:
        """``tables/ssw_mechanisms_all.csv`` (the target ``mechanisms``)."""
        return self.table(full=True)

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


#: This study's part of the plan (:attr:`chain.pipeline.plan.run_plan.RunPlan.parts`).
PART = MechanismPlan
