"""The C-sensitivity study's facts: its choices (estimator, eta, sensor pair, amplitude
range, one at a time from the headline choice) and its simulations, every sensor bead
of every pair recorded (:mod:`chain.studies.c_sensitivity`): a configured model's
simulate job records those of its eta, the study's own rule the others."""

from __future__ import annotations

from functools import cached_property

from chain.pipeline.plan import PartPlan
from chain.studies.c_sensitivity import sensitivity_plan, shifted_pairs


class CSensitivityPlan(PartPlan):
    """The facts of the c_sensitivity job."""

    @cached_property
    def choices(self) -> dict:
        """The study's choices (:func:`chain.studies.c_sensitivity.sensitivity_plan`,
        the run's speeds)."""
        return sensitivity_plan(self.plan.config, list(self.plan.speeds))

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

    def recorded_by(self, job: dict) -> str | None:
        """The configured model whose simulate job recorded the shots of ``job`` (one of
        :meth:`jobs`; its readings hold every bead's felt force), or None: a model with
        the same eta, read out as the felt force."""
        if job["readout"] != "felt":
            return None
        return next((m for m, eta in self.plan.models.items() if eta == job["eta_s"]), None)

    def readings(self) -> list[tuple[str, str, dict]]:
        """Where each simulation of :meth:`jobs` is recorded (every bead's felt force),
        in order: (rule, output, wildcards) of the configured model's ``simulate`` job
        (:meth:`recorded_by`), else of the study's own ``c_sensitivity_simulate`` job of
        its eta (wildcard ``eta``: the eta's index in the choices; output ``N<N>``)."""
        etas, found = self.choices["eta_s"], []
        for job in self.jobs():
            model, n = self.recorded_by(job), job["N"]
            eta = {"eta": etas.index(job["eta_s"])}
            found.append(("simulate", "readings", {"model": model, "N": n}) if model
                         else ("c_sensitivity_simulate", f"N{n}", eta))  # fmt: skip
        return found

    def job(self, eta: int, n_beads: int) -> dict:
        """The simulation of the ``eta``-th eta of the choices on the chain of N beads."""
        wanted = self.choices["eta_s"][int(eta)]
        return next(j for j in self.jobs() if j["eta_s"] == wanted and j["N"] == int(n_beads))
