"""The ablation study's part of the plan (the virtual experiment, a MODEL, not data):
one job per variant of ``ablation.variants`` reruns the virtual experiment of every
chain with one ingredient changed (:mod:`chain.studies.ablation`), analyses it as the
pipeline analyses the experiment, and fits C and a free exponent; ``ablation_table``
gathers the variants. Variants marked ``default_run`` are in the default run
(``tables/ablation_exponent.csv``); all of them: the target ``ablation``
(``tables/ablation_exponent_all.csv``). Nothing is simulated twice: a replicate with
the run's own settings reads the run's virtual experiment, and a variant identical to
one listed before it (its twin) copies that one's outputs."""

from __future__ import annotations

import json
from functools import cached_property

from chain.pipeline.config.ablation import ablation_variants, variant_settings, variant_tolerance
from chain.pipeline.plan.steps import Part, Step
from chain.studies.ablation_table import overrides_text
from chain.studies.mechanism_settings import CANDIDATE_REFERENCE


class AblationPlan(Part):
    """The ablation_variant, ablation_twin and ablation_table steps."""

    @cached_property
    def variants(self) -> dict[str, dict]:
        """Variant name -> variant (:func:`chain.pipeline.config.ablation.ablation_variants`)."""
        return {v["name"]: v for v in ablation_variants(self.plan.config)}

    def names(self, full: bool) -> list[str]:
        """Variants of tables/ablation_exponent.csv (the default run's: those with
        default_run that name no mechanism, not the candidates' reference; only with
        the virtual experiment and ``studies.ablation``), or with ``full`` of
        ablation_exponent_all.csv (all, whether the study is on or not: asked for)."""
        if full:
            return list(self.variants)
        if not (self.plan.experiment.virtual and self.plan.study("ablation")):
            return []
        return [
            name
            for name, v in self.variants.items()
            if v["default_run"] and not v["mechanism"] and name != CANDIDATE_REFERENCE
        ]

    def settings(self, name: str) -> list[list[dict]]:
        """Per replicate, the VirtualExperiment fields of every chain of one variant."""
        variant, config = self.variants[name], self.plan.config
        return [
            [variant_settings(config, variant, n, list(s), k) for n, s in self.plan.chains.items()]
            for k in range(variant["replicates"])
        ]

    def tolerance(self, name: str) -> float | None:
        """Acceptance tolerance of a variant; None keeps every collision shot."""
        return variant_tolerance(self.plan.config, self.variants[name])

    def datasets(self, name: str) -> list[list[str]]:
        """Per replicate of a variant, the run's virtual-experiment datasets (one folder
        per chain) when that replicate's settings are the run's virtual experiment's
        for every chain (its shots are those files, byte for byte), else ``[]``."""
        experiment = self.plan.experiment
        run = [experiment.settings(n) for n in self.plan.chains] if experiment.virtual else None
        return [
            [experiment.raw_dataset(n) for n in self.plan.chains] if chains == run else []
            for chains in self.settings(name)
        ]

    @cached_property
    def twins(self) -> dict[str, str]:
        """Variant -> the first variant listed before it with the same settings (every
        replicate) and tolerance, whose outputs are therefore its own; only variants
        that have such a twin."""
        first: dict[str, str] = {}
        twins = {}
        for name in self.variants:
            key = json.dumps([self.settings(name), self.tolerance(name)])
            if key in first:
                twins[name] = first[key]
            first.setdefault(key, name)
        return twins

    def files(self, name: str, what: str = "fits") -> str:
        """``ablation/<variant>_<what>.csv`` (fits or ssw_fits)."""
        return f"{self.plan.out}/ablation/{name}_{what}.csv"

    def _variant_params(self, name: str) -> dict:
        """A variant job's parameters: a replicate that reads the run's virtual
        experiment gets a flag, not the folders, whose path names the run."""
        return {
            "settings": self.settings(name),
            "reads_run": [bool(folders) for folders in self.datasets(name)],
            "tolerance": self.tolerance(name),
            "estimators": self.plan.config["analysis"]["estimators"],
            "series": self.plan.experiment.series,
        }

    def steps(self) -> list[Step]:
        """ablation_variant, ablation_twin, ablation_table."""
        plan, log = self.plan, f"{self.plan.out}/logs"
        outputs = {what: self.files("{variant}", what) for what in ("fits", "ssw_fits")}
        table = {"": self.names(full=False), "_all": self.names(full=True)}
        return [
            Step(
                "ablation_variant", outputs,
                jobs=[{"variant": v} for v in self.variants if v not in self.twins],
                inputs=lambda w: {"datasets": next(
                    (f for f in self.datasets(w["variant"]) if f), [])},
                params=lambda w: self._variant_params(w["variant"]),
                log=f"{log}/ablation/{{variant}}.log", priority=1,
            ),
            Step(
                "ablation_twin", outputs, jobs=[{"variant": v} for v in self.twins],
                inputs=lambda w: {what: self.files(self.twins[w["variant"]], what)
                                  for what in ("fits", "ssw_fits")},
                log=f"{log}/ablation/{{variant}}.log",
                shell="(cp {input.fits} {output.fits} && cp {input.ssw_fits} "
                "{output.ssw_fits}) > {log} 2>&1",
            ),
            Step(
                "ablation_table", {"0": f"{plan.tables}/ablation_exponent{{which}}.csv"},
                jobs=[{"which": which} for which, names in table.items() if names],
                inputs=lambda w: {"fits": [self.files(n) for n in table[w["which"]]]},
                params=lambda w: {
                    "variants": table[w["which"]],
                    "estimator": plan.config["analysis"]["main_estimator"],
                    "overrides": {n: overrides_text(v) for n, v in self.variants.items()},
                },
                log=f"{log}/tables/ablation_exponent{{which}}.log",
            ),
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """``tables/ablation_exponent.csv`` when the default run has variants."""
        return [f"{self.plan.tables}/ablation_exponent.csv"] if self.names(full=False) else []

    def full_targets(self) -> list[str]:
        """``tables/ablation_exponent_all.csv`` (the target ``ablation``)."""
        return [f"{self.plan.tables}/ablation_exponent_all.csv"] if self.variants else []


#: This study's part of the plan (:attr:`chain.pipeline.plan.run_plan.RunPlan.parts`).
PART = AblationPlan
