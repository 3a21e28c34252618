"""The simulation's part of the plan: one ``simulate`` job per model and chain (every
launch speed batched), the SSW tracked contact by contact (``ssw_track``, the long
chains too), and the field of the collision the space-time figure shows
(``ssw_fields``)."""

from __future__ import annotations

from chain.pipeline.plan.jobs import chain_of
from chain.pipeline.plan.resources import simulation_needs, simulation_threads
from chain.pipeline.plan.steps import Part, Step


class SimulationPlan(Part):
    """The simulate, ssw_track and ssw_fields steps of a run."""

    @property
    def parts(self) -> list[tuple[str, str, int]]:
        """(source, model, N) of each simulated trace file."""
        return [("simulation", m, n) for m in self.plan.models for n in self.plan.chains]

    def file(self, model: str, n_beads: int, what: str) -> str:
        """``simulation/<model>_N<N>_<what>.csv`` (traces, runs, ssw_track, field)."""
        return f"{self.plan.out}/simulation/{model}_N{n_beads}_{what}.csv"

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
        """Cores a simulate (or ssw_track) job is worth
        (:func:`chain.pipeline.plan.resources.simulation_threads`)."""
        job = self._job(wildcards)
        return simulation_threads(
            chain_of(job), len(job["speeds_m_s"]), max(job["speeds_m_s"]),
            job["duration_s"], job["time_step_s"],
        )  # fmt: skip

    def mem_mb(self, wildcards, threads) -> int:
        """Memory a simulate (or ssw_track) job asks a scheduler for, MB."""
        return self._needs(wildcards, threads).mem_mb

    def runtime(self, wildcards, threads) -> int:
        """Run time a simulate (or ssw_track) job asks a scheduler for, minutes."""
        return self._needs(wildcards, threads).runtime

    def _job(self, wildcards) -> dict:
        return self.plan.simulate_job(wildcards["model"], int(wildcards["N"]))

    def _needs(self, wildcards, threads):
        job = self._job(wildcards)
        return simulation_needs(
            chain_of(job), len(job["speeds_m_s"]), max(job["speeds_m_s"]), job["duration_s"],
            job["record_interval_s"], job["time_step_s"], threads,
        )  # fmt: skip

    def steps(self) -> list[Step]:
        """simulate, ssw_track and ssw_fields."""
        plan, first = self.plan, next(iter(self.plan.chains))
        log = f"{plan.out}/logs/simulate"
        needs = {"mem_mb": self.mem_mb, "runtime": self.runtime}
        fields = {f"N{n}": self.file(self.spacetime_model, n, "field") for n in self.field_chains}
        return [
            # First: the pulse table waits for them; the first chain of each model ahead
            # of the others, so that different kernels compile side by side on a fresh
            # clone and the rest load them from numba's cache.
            Step(
                "simulate",
                {"traces": self.file("{model}", "{N}", "traces"),
                 "runs": self.file("{model}", "{N}", "runs")},
                jobs=[{"model": m, "N": n} for m in plan.models for n in plan.chains],
                params=lambda w: {"job": self._job(w)},
                log=f"{log}/{{model}}_N{{N}}.log",
                priority=lambda w: 4 if int(w["N"]) == first else 3,
                threads=self.threads, resources=needs,
            ),
            # Each chain's collisions with every contact recorded, the SSW tracked;
            # half a simulate job's work, so its requests are an upper bound.
            Step(
                "ssw_track",
                {"track": self.file("{model}", "{N}", "ssw_track")},
                jobs=[{"model": m, "N": n} for m in plan.models for n in plan.tracked_chains],
                params=lambda w: {"job": self._job(w)},
                log=f"{log}/{{model}}_N{{N}}_ssw_track.log",
                priority=3, threads=self.threads, resources=needs,
            ),
            # The one collision the space-time figure shows, integrated again at
            # ssw_track's step (the same numbers bit for bit).
            Step(
                "ssw_fields",
                fields,
                inputs=lambda w: {
                    "tracks": [self.file(self.spacetime_model, n, "ssw_track")
                               for n in self.field_chains]
                },
                params=lambda w: {
                    "jobs": [plan.simulate_job(self.spacetime_model, n)
                             for n in self.field_chains],
                    "representative_force_N": plan.config["figures"]["representative_force_N"],
                    "representative_index": plan.config["figures"]["representative_index"],
                },
                log=f"{log}/ssw_fields.log",
                priority=3,
            ),
        ]  # fmt: skip
