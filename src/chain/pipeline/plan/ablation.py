"""The ablation study's facts (the virtual experiment, a MODEL, not data): its variants
(:mod:`chain.pipeline.config.ablation`), which of them the run makes (its ablation tables'
and the mechanism study's candidates), each variant's settings and tolerance."""

from __future__ import annotations

from functools import cached_property

from chain.pipeline.config.ablation import ablation_variants, variant_settings, variant_tolerance
from chain.pipeline.plan import PartPlan
from chain.studies.ablation_table import overrides_text
from chain.studies.mechanism_settings import CANDIDATE_REFERENCE, candidate_variants


class AblationPlan(PartPlan):
    """The facts of the ablation_shots and ablation_variants jobs."""

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

    def candidates(self, full: bool) -> dict[str, list[str]]:
        """Variant -> [mechanism, setting] of the mechanism study's candidates
        (:func:`chain.studies.mechanism_settings.candidate_variants`); none unless the
        experiment is virtual and ``studies.mechanisms`` on."""
        if not (self.plan.experiment.virtual and self.plan.study("mechanisms")):
            return {}
        found = candidate_variants(list(self.variants.values()), full)
        return {name: list(pair) for name, pair in found.items()}

    @property
    def made(self) -> list[str]:
        """The variants the run makes, in config order: its ablation tables' and the
        mechanism study's candidates (every one with ``studies.mechanisms: full``)."""
        every = self.plan.config["studies"]["mechanisms"] == "full"
        wanted = {*self.names(False), *self.candidates(every)}
        return [name for name in self.variants if self.full or name in wanted]

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

    def shots(self) -> dict[str, list[list[dict]]]:
        """Variant -> :meth:`settings` of :attr:`made`: what the shots depend on."""
        return {name: self.settings(name) for name in self.made}

    def job(self) -> dict[str, dict]:
        """Variant -> {settings: :meth:`settings`; tolerance: :meth:`tolerance`; ssw:
        whether its SSW is fitted (a candidate's)} of :attr:`made`."""
        candidates = self.candidates(self.plan.config["studies"]["mechanisms"] == "full")
        return {
            name: {"settings": self.settings(name), "tolerance": self.tolerance(name),
                   "ssw": name in candidates}
            for name in self.made
        }  # fmt: skip

    @property
    def overrides(self) -> dict[str, str]:
        """Variant -> what it changes, in words (a column of the table)."""
        return {name: overrides_text(v) for name, v in self.variants.items()}
