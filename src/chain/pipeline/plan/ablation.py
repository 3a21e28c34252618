"""The ablation study's facts (the virtual experiment, a MODEL, not data): its variants
(:mod:`chain.pipeline.config.ablation`), which of them the run makes, each variant's
settings and tolerance, the replicates that read the run's own virtual experiment,
and the variants whose settings repeat an earlier one's (twins: one job for both)."""

from __future__ import annotations

import json
from functools import cached_property

from chain.pipeline.config.ablation import ablation_variants, variant_settings, variant_tolerance
from chain.studies.ablation_table import overrides_text
from chain.studies.mechanism_settings import CANDIDATE_REFERENCE


class AblationPlan:
    """The facts of the ablation_variant and ablation_table jobs.

    Parameters
    ----------
    plan : RunPlan
        The run's plan, whose shared facts it reads.
    """

    def __init__(self, plan):
        self.plan = plan

    @cached_property
    def variants(self) -> dict[str, dict]:
        """Variant name -> variant (:func:`chain.pipeline.config.ablation.ablation_variants`)."""
        return {v["name"]: v for v in ablation_variants(self.plan.config)}

    @property
    def full(self) -> bool:
        """Whether the run makes every variant (``studies.ablation: full``)."""
        return self.plan.config["studies"]["ablation"] == "full"

    def names(self, full: bool) -> list[str]:
        """Variants of tables/ablation_exponent.csv (the default run's: those with
        default_run that name no mechanism, not the candidates' reference; only with
        the virtual experiment and ``studies.ablation``), or with ``full`` of
        ablation_exponent_all.csv (all)."""
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

    def reads_run(self, name: str) -> list[bool]:
        """Per replicate of a variant, whether its settings are the run's virtual
        experiment's for every chain: its shots are then that experiment's files, byte
        for byte, which the job reads instead of simulating them again."""
        experiment = self.plan.experiment
        run = [experiment.settings(n) for n in self.plan.chains] if experiment.virtual else None
        return [chains == run for chains in self.settings(name)]

    @cached_property
    def _firsts(self) -> dict[str, str]:
        first: dict[str, str] = {}
        for name in self.variants:
            key = json.dumps([self.settings(name), self.tolerance(name)])
            first.setdefault(key, name)
            first[name] = first[key]
        return {name: first[name] for name in self.variants}

    def job(self, name: str) -> str:
        """The variant whose job makes ``name``'s outputs: the first variant listed with
        the same settings (every replicate) and tolerance, itself if none."""
        return self._firsts[name]

    @property
    def overrides(self) -> dict[str, str]:
        """Variant -> what it changes, in words (a column of the table)."""
        return {name: overrides_text(v) for name, v in self.variants.items()}
