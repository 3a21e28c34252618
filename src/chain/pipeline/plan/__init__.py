"""The run plan: what a checked config makes the run do (its jobs, their inputs,
parameters and outputs, and the targets)."""


class PartPlan:
    """The facts one part of the run gives its rules, read from the run's plan.

    Parameters
    ----------
    plan : RunPlan
        The run's plan, whose shared facts it reads.
    """

    def __init__(self, plan):
        self.plan = plan
