"""The sweep's part of the plan (``whatif/sweep.yaml``: N over a range and several eta):
``tables/sweep.csv`` joins, per model and chain, C and the SSW slope with the model's
eta; ``fig_c_vs_N`` draws C(N) and the parity figure SSW(N) (both in the figure
registry). Made when ``figures.sweep_vs_N`` is set."""

from __future__ import annotations

from chain.pipeline.plan.steps import Part, Step


class SweepPlan(Part):
    """The sweep_table step."""

    def steps(self) -> list[Step]:
        """sweep_table, when the run makes the sweep's table."""
        plan, t = self.plan, self.plan.analysis.table
        if not plan.config["figures"]["sweep_vs_N"]:
            return []
        return [
            Step(
                "sweep_table", {"0": t("sweep")},
                inputs=lambda w: {"delay_fits": t("delay_fits"), "ssw_fits": t("ssw_fits")},
                params=lambda w: {"eta_s": plan.models,
                                  "estimator": plan.config["analysis"]["main_estimator"]},
                log=f"{plan.out}/logs/tables/sweep.log",
                report={"0": ("sweep_table.rst", "Tables")},
            )
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """``tables/sweep.csv`` when the run makes it."""
        return [self.plan.analysis.table("sweep")] if self.steps() else []
