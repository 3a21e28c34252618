"""The C-sensitivity study's facts: its choices (estimator, eta, sensor pair, amplitude
range, one at a time from the headline choice) and its simulations, every sensor bead
of every pair recorded (:mod:`chain.studies.c_sensitivity`)."""

from __future__ import annotations

from functools import cached_property

from chain.studies.c_sensitivity import sensitivity_plan, shifted_pairs


class CSensitivityPlan:
    """The facts of the c_sensitivity job.

    Parameters
    ----------
    plan : RunPlan
        The run's plan, whose shared facts it reads.
    """

    def __init__(self, plan):
        self.plan = plan

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
