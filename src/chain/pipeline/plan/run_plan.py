"""The run plan: what a checked config means for the run, derived once.

``common.smk`` makes ONE :class:`RunPlan` of the config after its schema (which fills in
every default) and :func:`chain.pipeline.config.check.check_config`. The plan holds the
facts every part shares (models, chains, launch speeds, durations) and composes the
parts of the run, each planning itself (:data:`CORE_PARTS` and each study the schema
names under ``studies``): their steps make every job of the run (:attr:`RunPlan.jobs`),
their files the targets. It reads no file but the measured datasets' metadata, and
knows no Snakemake.
"""

from __future__ import annotations

import copy
import importlib
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from chain.physics.model import ChainModel
from chain.pipeline.plan import analysis, experiment, figures, report, simulation, sweep
from chain.pipeline.plan.jobs import chain_of
from chain.pipeline.plan.steps import Jobs, Step

#: The parts every run has, in the order of the default run's files. Each study the
#: schema names under ``studies`` adds its own part, ``chain.pipeline.plan.<study>.PART``,
#: whether the config switches it on or not (its full target still runs it).
CORE_PARTS = (
    ("simulation", simulation.SimulationPlan),
    ("experiment", experiment.ExperimentPlan),
    ("analysis", analysis.AnalysisPlan),
    ("figures", figures.FigurePlan),
    ("report", report.ReportPlan),
    ("sweep", sweep.SweepPlan),
)


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


def _no_code(script: str) -> list[str]:
    return []


@dataclass(frozen=True, eq=False)
class RunPlan:
    """Every fact of a run, derived once from its checked config.

    Parameters
    ----------
    config : mapping
        The config after schema validation (defaults filled in) and
        :func:`chain.pipeline.config.check.check_config`; copied, never changed.
    root : str
        Folder that relative dataset paths start from (the working directory).
    code : callable
        Script name -> the source files the script runs (each job's ``lib`` input;
        :func:`chain.pipeline.plan.code.script_sources`); none by default.
    workflow_dir : str
        The workflow's folder (holding ``workflow/``), relative to the working directory.
    provenance : mapping
        Commit, config hash and versions of the run
        (:func:`chain.pipeline.provenance.record.run_provenance`), which the summary and
        the article state.

    Attributes
    ----------
    run_name, out, tables, figures_dir : str
        The run's name and its output folders (``results/<run_name>``, its
        ``tables`` and ``figures``), relative to the working directory.
    models, chains : dict
        Model name -> Kuwabara-Kono time eta, s; N -> sensor beads (S1, S2).
    long_chains : tuple of int
        N of the long chains (collisions only, every contact recorded, no sensors).
    speeds : tuple of float
        Launch speeds V0, m/s (:func:`launch_speeds`).
    traces_n : tuple of int
        Chains of Figs. 2 and 3 and the space-time figure (``figures.traces_N``, or all).
    parts : tuple of str
        The parts of the run (:data:`CORE_PARTS`, then the studies), each an attribute.
    """

    config: Mapping
    root: str = "."
    code: Callable[[str], list[str]] = _no_code
    workflow_dir: str = "."
    provenance: Mapping = field(default_factory=dict)
    run_name: str = field(init=False)
    out: str = field(init=False)
    tables: str = field(init=False)
    figures_dir: str = field(init=False)
    models: dict[str, float] = field(init=False)
    chains: dict[int, tuple[int, ...]] = field(init=False)
    long_chains: tuple[int, ...] = field(init=False)
    speeds: tuple[float, ...] = field(init=False)
    traces_n: tuple[int, ...] = field(init=False)
    parts: tuple[str, ...] = field(init=False)

    def __post_init__(self) -> None:
        config = copy.deepcopy(dict(self.config))
        out = f"results/{config['run_name']}"
        chains = {int(c["N"]): tuple(int(b) for b in c["sensors"]) for c in config["chains"]}
        derived = {
            "config": config,
            "run_name": config["run_name"],
            "out": out,
            "tables": f"{out}/tables",
            "figures_dir": f"{out}/figures",
            "models": {m["name"]: m["eta_s"] for m in config["models"]},
            "chains": chains,
            "long_chains": tuple(int(n) for n in config["long_chains"]["N"]),
            "speeds": launch_speeds(config["launch"]),
            "traces_n": tuple(config["figures"]["traces_N"] or chains),
        }
        studies = [(name, importlib.import_module(f"{__package__}.{name}").PART)
                   for name in config["studies"]]  # fmt: skip
        derived["parts"] = tuple(name for name, _ in (*CORE_PARTS, *studies))
        for name, value in derived.items():
            object.__setattr__(self, name, value)
        for name, part in (*CORE_PARTS, *studies):
            object.__setattr__(self, name, part(self))

    # ---- chains and their simulation jobs ---------------------------------------------

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
        """The chain that the simulate (and ssw_track) job of a model and N integrates."""
        return chain_of(self.simulate_job(model, n_beads))

    @cached_property
    def conservative(self) -> tuple[str, ...]:
        """Models without dissipation (:attr:`chain.physics.model.ChainModel.is_conservative`):
        their energy drift is the integrator's error."""
        first = next(iter(self.chains))
        return tuple(m for m in self.models if self.chain(m, first).is_conservative)

    # ---- studies, steps, targets --------------------------------------------------------

    def study(self, name: str) -> bool:
        """Whether the run makes the study ``name`` (config ``studies.<name>``)."""
        return bool(self.config["studies"][name])

    @property
    def studies_not_run(self) -> list[str]:
        """The studies the config switches off, in the schema's order."""
        return [name for name, on in self.config["studies"].items() if not on]

    @cached_property
    def steps(self) -> list[Step]:
        """Every step (rule) of the run, part by part; a step with no job is left out
        (its rule would have nothing to make)."""
        steps = [step for name in self.parts for step in getattr(self, name).steps()]
        return [step for step in steps if step.jobs]

    @cached_property
    def jobs(self) -> Jobs:
        """Every job the plan may ask for, found by output or by rule and wildcards."""
        return Jobs(self.steps, self.code)

    def targets(self) -> list[str]:
        """Every file of the default run (rule all), relative to the working directory."""
        return [path for name in self.parts for path in getattr(self, name).targets()]

    def target_rules(self) -> dict[str, list[str]]:
        """Rule name -> the files it asks for, of the rules that only gather files:
        ``all`` (the default run) and the studies' full runs (``ablation``,
        ``mechanisms``)."""
        return {
            "all": self.targets(),
            "ablation": self.ablation.full_targets(),
            "mechanisms": self.mechanisms.full_targets(),
        }

    def target_files(self, names) -> list[str]:
        """The files a command line's targets ask for: a gathering rule's files
        (:meth:`target_rules`; ``report`` builds the default run first), a step's
        outputs (a step of one job named by its rule), or a file; none named: the
        default run's.

        Parameters
        ----------
        names : iterable of str
            Snakemake's targets (rule names or paths).
        """
        rules = self.target_rules() | {"report": self.targets()}
        files = []
        for name in names or ["all"]:
            if name in rules:
                files += rules[name]
            elif name in self.jobs.steps and not self.jobs.steps[name].wildcard_names:
                files += self.jobs.of(name, {}).outputs.values()
            else:
                files.append(os.path.normpath(os.path.relpath(name)))
        return files

    def notes(self) -> list[str]:
        """What the console says about the plan before any job (a part skipped)."""
        return [note for name in self.parts for note in getattr(self, name).notes()]
