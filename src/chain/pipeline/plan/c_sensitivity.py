"""The C-sensitivity study's part of the plan: how much C depends on our choices
(estimator, eta, sensor pair, amplitude range, one at a time from the headline choice),
on shots simulated anew with every sensor bead of every pair recorded
(:mod:`chain.studies.c_sensitivity`). One job computes the table for every estimator as
the headline one (the simulations are the cost), so that a what-if choosing another
main estimator reuses it; ``c_sensitivity_table`` picks the main one."""

from __future__ import annotations

from functools import cached_property

from chain.pipeline.plan.steps import Part, Step
from chain.studies.c_sensitivity import sensitivity_plan, shifted_pairs


class CSensitivityPlan(Part):
    """The c_sensitivity and c_sensitivity_table steps (with ``studies.c_sensitivity``)."""

    @cached_property
    def choices(self) -> dict:
        """The study's choices (:func:`chain.studies.c_sensitivity.sensitivity_plan`,
        the run's speeds)."""
        return sensitivity_plan(self.plan.config, list(self.plan.speeds))

    @property
    def every_estimator(self) -> dict:
        """:attr:`choices` without the main estimator (the job computes the table for
        every estimator as the headline one)."""
        return {k: v for k, v in self.choices.items() if k != "main_estimator"}

    def jobs(self) -> list[dict]:
        """The study's simulations, per eta then chain: every bead of every sensor pair
        recorded (:meth:`RunPlan.simulate_job` inputs)."""
        choices, jobs = self.choices, []
        for eta in choices["eta_s"]:
            for n in choices["chains"]:
                pairs = [shifted_pairs(choices["chains"], s)[n] for s in [0, *choices["shifts"]]]
                beads = sorted({b for pair in pairs for b in pair})
                name = f"eta{eta * 1e6:.3g}us"
                jobs.append(self.plan.simulate_job(name, n, eta_s=eta, sensors=beads))
        return jobs

    def steps(self) -> list[Step]:
        """c_sensitivity, c_sensitivity_table."""
        if not self.plan.study("c_sensitivity"):
            return []
        plan, every = self.plan, f"{self.plan.out}/c_sensitivity/every_estimator.csv"
        return [
            Step(
                "c_sensitivity", {"0": every},
                params=lambda w: {"plan": self.every_estimator, "jobs": self.jobs()},
                log=f"{plan.out}/logs/c_sensitivity/every_estimator.log", priority=1,
            ),
            Step(
                "c_sensitivity_table", {"0": plan.analysis.table("c_sensitivity")},
                inputs=lambda w: {"table": every}, script="main_estimator_rows",
                params=lambda w: {
                    "column": "main_estimator",
                    "estimator": plan.config["analysis"]["main_estimator"],
                },
                log=f"{plan.out}/logs/tables/c_sensitivity.log",
            ),
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """``tables/c_sensitivity.csv`` when the study runs."""
        return (
            [self.plan.analysis.table("c_sensitivity")] if self.plan.study("c_sensitivity") else []
        )


#: This study's part of the plan (:attr:`chain.pipeline.plan.run_plan.RunPlan.parts`).
PART = CSensitivityPlan
