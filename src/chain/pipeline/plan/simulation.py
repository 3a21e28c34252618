"""The simulation's facts: the chains of the space-time figure, and what a simulate
(or long_chain) job asks a scheduler for."""

from __future__ import annotations

from chain.pipeline.plan import PartPlan
from chain.pipeline.plan.jobs import chain_of
from chain.pipeline.plan.resources import simulation_needs, simulation_threads


class SimulationPlan(PartPlan):
    """The facts of the simulate and long_chain jobs of a run."""

    @property
    def field_chains(self) -> tuple[int, ...]:
        """Chains whose field the space-time figure shows: Fig. 3's, then the long ones."""
        return (*self.plan.traces_n, *self.plan.long_chains)

    @property
    def spacetime_model(self) -> str:
        """Model of the space-time figure: the first conservative model (where the SSW
        is a clean wave), or Fig. 3's model if none."""
        return (self.plan.conservative or (self.plan.config["figures"]["traces_model"],))[0]

    def threads(self, wildcards) -> int:
        """Cores a simulate (or long_chain) job is worth
        (:func:`chain.pipeline.plan.resources.simulation_threads`)."""
        job = self._job(wildcards)
        return simulation_threads(
            chain_of(job), len(job["speeds_m_s"]), max(job["speeds_m_s"]),
            job["duration_s"], job["time_step_s"],
        )  # fmt: skip

    def mem_mb(self, wildcards, threads) -> int:
        """Memory a simulate (or long_chain) job asks a scheduler for, MB."""
        return self._needs(wildcards, threads).mem_mb

    def runtime(self, wildcards, threads) -> int:
        """Run time a simulate (or long_chain) job asks a scheduler for, minutes."""
        return self._needs(wildcards, threads).runtime

    def _job(self, wildcards) -> dict:
        return self.plan.simulate_job(wildcards["model"], int(wildcards["N"]))

    def _needs(self, wildcards, threads):
        job = self._job(wildcards)
        return simulation_needs(
            chain_of(job), len(job["speeds_m_s"]), max(job["speeds_m_s"]), job["duration_s"],
            job["record_interval_s"], job["time_step_s"], threads,
        )  # fmt: skip
