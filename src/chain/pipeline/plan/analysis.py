"""The analysis's part of the plan: pulses (cos^6 fits) of every trace file, then the
crossing delays, the secondary solitary waves (SSW) and their fits, and the SSW along
the chain, as the contract tables. The analysis takes well under a second per trace
file, so each table is one job."""

from __future__ import annotations

from chain.pipeline.plan.steps import Part, Step

#: The contract tables of every run (tables/<name>.csv), in order.
TABLES = tuple("pulses delays delay_fits ssw ssw_fits ssw_track ssw_speed".split())

#: What a job reading one trace file at a time asks a scheduler for: MB (185 MB peak)
#: and minutes (~2 s per trace file).
PER_TRACE_FILE = {"mem_mb": 1000, "runtime": 30}


class AnalysisPlan(Part):
    """The pulses, delays, delay_fits, ssw, ssw_fits and ssw_speed steps."""

    def table(self, name: str) -> str:
        """``tables/<name>.csv`` of the run."""
        return f"{self.plan.tables}/{name}.csv"

    def trace_files(self) -> list[str]:
        """Every trace file the analysis reads: the simulation's and the experiment's."""
        sim = self.plan.simulation
        files = [sim.file(m, n, "traces") for _, m, n in sim.parts]
        return files + self.plan.experiment.trace_files()

    def track_files(self) -> list[str]:
        """Every model's SSW track of every tracked chain (the long ones included)."""
        sim = self.plan.simulation
        return [sim.file(m, n, "ssw_track") for m in self.plan.models
                for n in self.plan.tracked_chains]  # fmt: skip

    def steps(self) -> list[Step]:
        """pulses, delays, delay_fits, ssw, ssw_fits, ssw_speed."""
        plan, t = self.plan, self.table
        config, log = plan.config, f"{plan.out}/logs/tables"
        selection = plan.experiment.selection_files()
        estimator = {"estimator": config["analysis"]["main_estimator"]}
        return [
            Step(
                "pulses", {"0": t("pulses")}, inputs=lambda w: {"traces": self.trace_files()},
                params=lambda w: {"estimators": config["analysis"]["estimators"]},
                log=f"{log}/pulses.log", priority=2, resources=PER_TRACE_FILE,
                report={"0": ("pulses.rst", "Tables")},
            ),
            Step(
                "delays", {"0": t("delays")},
                inputs=lambda w: {"pulses": t("pulses"), "selection": selection},
                log=f"{log}/delays.log", priority=1,
            ),
            Step(
                "delay_fits", {"0": t("delay_fits")}, inputs=lambda w: {"delays": t("delays")},
                log=f"{log}/delay_fits.log", priority=1,
                report={"0": ("delay_fits.rst", "Tables")},
            ),
            Step(
                "ssw", {"0": t("ssw")},
                inputs=lambda w: {
                    "traces": self.trace_files(), "pulses": t("pulses"), "selection": selection,
                },
                params=lambda w: estimator, log=f"{log}/ssw.log", priority=2,
                resources=PER_TRACE_FILE,
            ),
            Step(
                "ssw_fits", {"0": t("ssw_fits")}, inputs=lambda w: {"ssw": t("ssw")},
                log=f"{log}/ssw_fits.log", priority=1,
                report={"0": ("ssw_fits.rst", "Tables")},
            ),
            Step(
                "ssw_speed", {"track": t("ssw_track"), "speed": t("ssw_speed")},
                inputs=lambda w: {"tracks": self.track_files()},
                params=lambda w: {"material": config["material"], "radius_m": config["radius_m"]},
                log=f"{log}/ssw_speed.log", priority=1,
            ),
        ]  # fmt: skip

    def targets(self) -> list[str]:
        """The contract tables (:data:`TABLES`)."""
        return [self.table(name) for name in TABLES]
