"""The experiment's part of the plan: its traces in the trace format, and the paper's
acceptance protocol on them. With ``experiment.source: virtual``, ``virtual_experiment``
writes each chain's dataset in the measured format (a MODEL of the apparatus); with
``measured``, the datasets of ``experiment.datasets`` are read instead; with ``none``
nothing here runs and Fig. 2 is not drawn. ``experiment_traces`` loads the datasets,
``selection`` applies the 5 % amplitude match (``experiment/selection.csv``), which the
delay and SSW tables use to drop rejected collision shots.
"""

from __future__ import annotations

from functools import cached_property

from chain.apparatus.virtual_settings import VirtualExperiment
from chain.labels import VIRTUAL_SERIES
from chain.pipeline.config.virtual import virtual_experiment_settings
from chain.pipeline.plan.datasets import (
    DEFAULT_CACHE,
    ExperimentPart,
    bad_channel_policy,
    experiment_label,
    experiment_parts,
)
from chain.pipeline.plan.steps import Part, Step


class ExperimentPlan(Part):
    """The virtual_experiment, experiment_traces and selection steps of a run."""

    @cached_property
    def chains(self) -> tuple[ExperimentPart, ...]:
        """The experiment's chains (:func:`chain.pipeline.plan.datasets.experiment_parts`;
        reads the measured datasets' metadata when first asked)."""
        return tuple(experiment_parts(self.plan.config, root=self.plan.root))

    @cached_property
    def label(self) -> str:
        """How figures and the summary name the experiment series."""
        return experiment_label(list(self.chains))

    @property
    def virtual(self) -> bool:
        """Whether the experiment is the virtual experiment (``experiment.source``)."""
        return self.plan.config["experiment"]["source"] == "virtual"

    @property
    def series(self) -> str:
        """Series name of the virtual experiment's datasets."""
        return self.plan.config["experiment"]["name"] or VIRTUAL_SERIES

    def settings(self, n_beads: int) -> dict:
        """Every input of the virtual experiment of the chain of N beads: the fields of
        :class:`~chain.apparatus.virtual_settings.VirtualExperiment` as plain values,
        ``experiment.virtual`` under its own names, the seed the run's + N."""
        n = int(n_beads)
        return virtual_experiment_settings(self.plan.config, n, self.plan.chains[n])

    def model(self, n_beads: int) -> VirtualExperiment:
        """The virtual experiment of the chain of N beads (:meth:`settings`)."""
        return VirtualExperiment(**self.settings(n_beads))

    def raw_dataset(self, n_beads: int) -> str:
        """Folder of the virtual experiment's dataset of the chain of N beads."""
        return f"{self.plan.out}/experiment/raw/N{int(n_beads)}"

    @property
    def parts(self) -> list[tuple[str, str, int]]:
        """(source, name, N) of each experiment trace file."""
        return [("experiment", part.name, part.n_beads) for part in self.chains]

    def trace_files(self, shown: tuple[int, ...] = ()) -> list[str]:
        """The experiment's trace files; with ``shown``, those of these N (all if none)."""
        files = [(n, f"{self.plan.out}/experiment/{name}_N{n}_traces.csv")
                 for _, name, n in self.parts]  # fmt: skip
        return [f for n, f in files if n in shown] or [f for _, f in files]

    def selection_files(self) -> list[str]:
        """``[experiment/selection.csv]`` when the run has an experiment, else ``[]``."""
        return [f"{self.plan.out}/experiment/selection.csv"] if self.chains else []

    def _datasets(self) -> dict:
        """The inputs and parameters that load the datasets: the virtual experiment's
        folders as inputs (a path naming the run in a parameter would make every run's
        result its own), each measured dataset's files, and the policy on bad channels."""
        return {
            "virtual": [self.raw_dataset(p.n_beads) for p in self.chains if p.folder is None],
            "measured": [path for p in self.chains if p.folder is not None for path in p.files],
            "datasets": [{"folder": p.folder, "name": p.name, "N": p.n_beads} for p in self.chains],
            "bad_channels": bad_channel_policy(self.plan.config),
            "cache": str(DEFAULT_CACHE),
        }

    def steps(self) -> list[Step]:
        """virtual_experiment, experiment_traces, selection."""
        if not self.chains:
            return []
        plan, out, d = self.plan, self.plan.out, self._datasets()
        load = {k: d[k] for k in ("datasets", "bad_channels", "cache")}
        virtual = [{"N": p.n_beads} for p in self.chains if p.folder is None]
        return [
            # ~1.3 s of integration per chain: a second core would shorten it by less
            # than the job another core runs meanwhile.
            Step(
                "virtual_experiment", {"0": f"{out}/experiment/raw/N{{N}}"}, jobs=virtual,
                params=lambda w: {"settings": self.settings(w["N"]), "dataset": self.series},
                log=f"{out}/logs/experiment/virtual_N{{N}}.log", folders=("0",), priority=3,
                resources={"mem_mb": 1000, "runtime": 30},  # MB (270 peak); minutes
            ),
            # One job loads every dataset: a job costs more start-up than a load.
            Step(
                "experiment_traces",
                {str(i): path for i, path in enumerate(self.trace_files())},
                inputs=lambda w: {"virtual": d["virtual"], "measured": d["measured"]},
                params=lambda w: load,
                log=f"{out}/logs/experiment/traces.log", priority=3,
            ),
            Step(
                "selection", {"0": self.selection_files()[0]},
                inputs=lambda w: {
                    "pulses": f"{plan.tables}/pulses.csv", "traces": self.trace_files(),
                    "virtual": d["virtual"], "measured": d["measured"],
                },
                params=lambda w: {
                    "tolerance": plan.config["experiment"]["tolerance"],
                    "estimator": plan.config["analysis"]["main_estimator"], **load,
                },
                log=f"{out}/logs/experiment/selection.log", priority=2,
                report={"0": ("selection.rst", "Tables")},
            ),
        ]  # fmt: skip
