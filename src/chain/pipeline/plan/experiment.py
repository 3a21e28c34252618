"""The experiment's facts: its chains and where their traces come from. With
``experiment.source: virtual``, the virtual experiment writes each chain's dataset in
the measured format (a MODEL of the apparatus); with ``measured``, the datasets of
``experiment.datasets`` are read instead (and checked before any job); with ``none``
there is no experiment and Fig. 2 is not drawn.
"""

from __future__ import annotations

from functools import cached_property

from chain.apparatus.virtual_settings import VirtualExperiment
from chain.labels import VIRTUAL_SERIES
from chain.pipeline.config.virtual import virtual_experiment_settings
from chain.pipeline.plan import PartPlan
from chain.pipeline.plan.datasets import (
    DEFAULT_CACHE,
    ExperimentPart,
    bad_channel_policy,
    check_experiment_datasets,
    experiment_label,
    experiment_parts,
)


class ExperimentPlan(PartPlan):
    """The facts of the virtual_experiment, experiment_traces and selection jobs."""

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

    @property
    def virtual_n(self) -> list[int]:
        """N of each chain the virtual experiment runs (none for measured datasets)."""
        return [part.n_beads for part in self.chains if part.folder is None]

    @property
    def measured_files(self) -> list[str]:
        """Every file of the measured datasets (``metadata.yaml`` and the shots)."""
        return [path for part in self.chains if part.folder is not None for path in part.files]

    @property
    def trace_files(self) -> dict[str, str]:
        """Output name -> file name of each chain's trace file (``series<i>``)."""
        return {f"series{i}": f"experiment/{part.name}_N{part.n_beads}_traces.csv"
                for i, part in enumerate(self.chains)}  # fmt: skip

    def shown(self, chains: tuple[int, ...] = ()) -> list[str]:
        """Output names of the trace files of the chains ``chains`` (all if none are)."""
        names = [name for name, part in zip(self.trace_files, self.chains, strict=True)
                 if part.n_beads in chains]  # fmt: skip
        return names or list(self.trace_files)

    @property
    def loading(self) -> dict:
        """The params that load the datasets: each dataset (measured folder or None, series
        name, N), the policy on bad channels and the dataset check's cache."""
        return {
            "datasets": [{"folder": p.folder, "name": p.name, "N": p.n_beads} for p in self.chains],
            "bad_channels": bad_channel_policy(self.plan.config),
            "cache": str(DEFAULT_CACHE),
        }

    def check_datasets(self) -> None:
        """Check every shot file of every measured dataset: all problems at once, before
        any job (:func:`chain.pipeline.plan.datasets.check_experiment_datasets`)."""
        check_experiment_datasets(self.plan.config, list(self.chains), root=self.plan.root)
