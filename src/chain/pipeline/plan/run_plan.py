"""The run plan: what a checked config means for the run, derived once.

``common.smk`` makes ONE :class:`RunPlan` of the config after its schema (which fills in
every default) and :func:`chain.pipeline.config.check.check_config`. The plan holds the
facts the rules share (models, chains, launch speeds, durations, each simulation's
inputs) and those of the simulation (:attr:`RunPlan.simulation`) and the experiment
(:attr:`RunPlan.experiment`); a study's rule file makes its own part from it. It reads
no file but the measured datasets' metadata, and knows no Snakemake.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from functools import cached_property

import numpy as np

from chain.physics.model import ChainModel
from chain.pipeline.plan.experiment import ExperimentPlan
from chain.pipeline.plan.jobs import chain_of
from chain.pipeline.plan.simulation import SimulationPlan


def launch_speeds(launch: Mapping) -> tuple[float, ...]:
    """The launch speeds V0 of a config's ``launch`` section, m/s: geometric from
    ``v0_min_m_s`` to ``v0_max_m_s``, ``count`` of them, rounded to 12 significant
    digits so that they print as stable text (rule parameters, file contents)."""
    speeds = np.geomspace(launch["v0_min_m_s"], launch["v0_max_m_s"], launch["count"])
    return tuple(float(f"{v:.12g}") for v in speeds)


def long_chain_duration(config: Mapping, n_beads: int) -> float:
    """Simulated time of a long chain, s: ``long_chains.duration_s``, or by default
    ``simulation.duration_s`` x N / the largest N of ``chains``.

    Parameters
    ----------
    config : mapping
        A schema-valid config (defaults filled in).
    n_beads : int
        N of the long chain.
    """
    duration = config["long_chains"]["duration_s"]
    if duration is not None:
        return float(duration)
    longest = max(entry["N"] for entry in config["chains"])
    return float(config["simulation"]["duration_s"]) * n_beads / longest


class RunPlan:
    """Every shared fact of a run, derived once from its checked config.

    Parameters
    ----------
    config : mapping
        The config after schema validation (defaults filled in) and
        :func:`chain.pipeline.config.check.check_config`; copied, never changed.
    root : str
        Folder that relative dataset paths start from (the working directory).
    provenance : mapping
        Commit, config hash and versions of the run
        (:func:`chain.pipeline.provenance.record.run_provenance`), which the summary and
        the article state.

    Attributes
    ----------
    run_name, out : str
        The run's name and its folder (``results/<run_name>``, relative to the working
        directory).
    models, chains : dict
        Model name -> Kuwabara-Kono time eta, s; N -> sensor beads (S1, S2).
    long_chains : tuple of int
        N of the long chains (collisions only, every contact recorded, no sensors).
    speeds : tuple of float
        Launch speeds V0, m/s (:func:`launch_speeds`).
    traces_n : tuple of int
        Chains of Figs. 2 and 3 and the space-time figure (``figures.traces_N``, or all).
    simulation, experiment : SimulationPlan, ExperimentPlan
        The facts of the simulation's and the experiment's jobs.
    """

    def __init__(self, config: Mapping, root: str = ".", provenance: Mapping | None = None):
        self.config = config = copy.deepcopy(dict(config))
        self.root, self.provenance = root, dict(provenance or {})
        self.run_name = config["run_name"]
        self.out = f"results/{self.run_name}"
        self.models = {m["name"]: m["eta_s"] for m in config["models"]}
        self.chains = {int(c["N"]): tuple(int(b) for b in c["sensors"]) for c in config["chains"]}
        self.long_chains = tuple(int(n) for n in config["long_chains"]["N"])
        self.speeds = launch_speeds(config["launch"])
        self.traces_n = tuple(config["figures"]["traces_N"] or self.chains)
        self.simulation = SimulationPlan(self)
        self.experiment = ExperimentPlan(self)

    @property
    def tracked_chains(self) -> tuple[int, ...]:
        """Chains whose SSW is tracked contact by contact: the chains, then the long ones."""
        return (*self.chains, *self.long_chains)

    def sensors(self, n_beads: int) -> tuple[int, ...]:
        """Sensor beads of the chain of N beads, S1 first (none for a long chain)."""
        return self.chains.get(int(n_beads), ())

    def duration(self, n_beads: int) -> float:
        """Simulated time of the chain of N beads, s (long chains: in proportion to N)."""
        if int(n_beads) in self.chains:
            return float(self.config["simulation"]["duration_s"])
        return long_chain_duration(self.config, int(n_beads))

    def simulate_job(
        self,
        model: str,
        n_beads: int,
        *,
        eta_s: float | None = None,
        sensors: Sequence[int] | None = None,
    ) -> dict:
        """Every input that determines one simulation of a model and chain, as a
        JSON-serialisable dict (:data:`chain.pipeline.plan.jobs.JOB_KEYS`; m, s, m/s):
        the chain, speeds, durations, step, record interval, readout. Analysis and
        figure keys are not in it; nor is a seed (the simulation draws nothing).

        Parameters
        ----------
        model : str
            A configured model; with ``eta_s`` given, any name (the ``model`` column).
        n_beads : int
            A configured chain or long chain.
        eta_s : float, optional
            Kuwabara-Kono time, s, instead of the model's (a study's chain).
        sensors : sequence of int, optional
            Beads to record instead of the chain's sensors (a study's chain).
        """
        n = int(n_beads)
        if n not in self.chains and n not in self.long_chains:
            raise KeyError(f"N = {n} is neither a configured chain nor a long chain")
        sim = self.config["simulation"]
        return {
            "model": str(model),
            "N": n,
            "sensors": [int(b) for b in (self.sensors(n) if sensors is None else sensors)],
            "material": self.config["material"],
            "radius_m": float(self.config["radius_m"]),
            "eta_s": float(self.models[model] if eta_s is None else eta_s),
            "readout": sim["readout"],
            "speeds_m_s": list(self.speeds),
            "duration_s": self.duration(n),
            "time_step_s": sim["time_step_s"],
            "record_interval_s": float(sim["record_interval_s"]),
            "max_energy_drift": float(sim["max_energy_drift"]),
        }

    def chain(self, model: str, n_beads: int) -> ChainModel:
        """The chain that the simulate (or long_chain) job of a model and N integrates."""
        return chain_of(self.simulate_job(model, n_beads))

    @cached_property
    def conservative(self) -> tuple[str, ...]:
        """Models without dissipation (:attr:`chain.physics.model.ChainModel.is_conservative`):
        their energy drift is the integrator's error."""
        first = next(iter(self.chains))
        return tuple(m for m in self.models if self.chain(m, first).is_conservative)

    def study(self, name: str) -> bool:
        """Whether the run makes the study ``name`` (config ``studies.<name>``)."""
        return bool(self.config["studies"][name])

    @property
    def studies_not_run(self) -> list[str]:
        """The studies the config switches off, in the schema's order."""
        return [name for name, on in self.config["studies"].items() if not on]

    @property
    def article_setup(self) -> dict:
        """The configuration the article states: chains, models, launch, the experiment."""
        config = self.config
        setup = {key: config[key] for key in ("chains", "models", "launch")}
        return setup | {
            "source": config["experiment"]["source"],
            "virtual": config["experiment"]["virtual"],
            "striker_radius_m": config["setup"]["striker_radius_m"],
            "tolerance": config["experiment"]["tolerance"],
        }
