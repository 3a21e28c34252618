"""The report's part of the plan: ``summary.json`` (the run's numbers beside the
paper's), ``summary.md`` from it (its own job, so that rewording the table reruns
nothing else), and ``article.pdf``, compiled by the typst package from
``workflow/report/article.typ`` with the run's numbers and figures."""

from __future__ import annotations

import os

from chain.pipeline.plan.steps import Part, Step
from chain.studies.mechanism_table import FRICTION_MECHANISM, REFERENCE_MECHANISM


class ReportPlan(Part):
    """The summary, summary_md and article steps."""

    def _summary_inputs(self) -> dict:
        plan, t = self.plan, self.plan.analysis.table
        sim = plan.simulation
        return {
            "delay_fits": t("delay_fits"), "ssw_fits": t("ssw_fits"),
            "c_sensitivity": plan.c_sensitivity.targets(),
            "ablation": plan.ablation.targets(),
            "mechanisms": plan.mechanisms.table(full=False),
            "lammps_check": plan.mechanisms.check_table(),
            "pulses": t("pulses"), "delays": t("delays"), "ssw": t("ssw"),
            "ssw_speed": t("ssw_speed"), "selection": plan.experiment.selection_files(),
            "runs": [sim.file(m, n, "runs") for _, m, n in sim.parts],
        }  # fmt: skip

    def _summary_params(self) -> dict:
        config = self.plan.config
        return {
            "run_name": self.plan.run_name,
            "material": config["material"],
            "radius_m": config["radius_m"],
            "conservative_models": list(self.plan.conservative),
            "estimator": config["analysis"]["main_estimator"],
            "experiment_label": self.plan.experiment.label,
            "tolerance": config["experiment"]["tolerance"],
            "friction_mechanism": FRICTION_MECHANISM,
            "reference_mechanism": REFERENCE_MECHANISM,
            # The studies switched off (summary.md and the article say they did not run).
            "studies_not_run": self.plan.studies_not_run,
            # Commit, config hash, installed versions and how they compare with the lock.
            "provenance": self.plan.provenance,
        }

    def _article_params(self) -> dict:
        config = self.plan.config
        setup = {key: config[key] for key in ("chains", "models", "launch")}
        setup |= {
            "source": config["experiment"]["source"],
            "virtual": config["experiment"]["virtual"],
            "striker_radius_m": config["setup"]["striker_radius_m"],
            "tolerance": config["experiment"]["tolerance"],
        }
        # A changed commit or configuration rebuilds the article, which states them.
        return {"setup": setup, "provenance": self.plan.provenance}

    def steps(self) -> list[Step]:
        """summary, summary_md, article."""
        plan, out = self.plan, self.plan.out
        t, figures = plan.analysis.table, plan.figures
        source = os.path.relpath(os.path.join(plan.workflow_dir, "workflow/report/article.typ"))
        return [
            Step(
                "summary", {"json": f"{out}/summary.json"},
                inputs=lambda w: self._summary_inputs(), params=lambda w: self._summary_params(),
                log=f"{out}/logs/summary.log",
            ),
            Step(
                "summary_md", {"md": f"{out}/summary.md"},
                inputs=lambda w: {"json": f"{out}/summary.json"},
                log=f"{out}/logs/summary_md.log",
                report={"md": ("summary.rst", "Summary")},
            ),
            Step(
                "article", {"0": f"{out}/article.pdf"},
                inputs=lambda w: {
                    "source": source, "summary": f"{out}/summary.json",
                    "delays": t("delays"), "ssw": t("ssw"),
                    "figures": [figures.files(name)[0] for name in figures.names()],
                },
                params=lambda w: self._article_params(),
                log=f"{out}/logs/article.log",
            ),
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """summary.json, summary.md and article.pdf."""
        out = self.plan.out
        return [f"{out}/summary.json", f"{out}/summary.md", f"{out}/article.pdf"]
