"""The run plan: what a checked config means for the run, derived once.

The Snakefile validates the config against its schema (which fills in every default)
and checks it (:func:`chain.pipeline.config.check.check_config`); ``workflow/rules/common.smk``
then makes ONE :class:`RunPlan` of it, and the rules ask the plan: the models and
chains, the launch speeds (computed here only), the simulated durations, which models
are conservative, the chain a job integrates and the job's inputs
(:meth:`RunPlan.simulate_job`), the experiment's parts and label, the virtual
experiment of each chain, which studies run with which settings, and the targets.
Nothing else derives a fact of the config; a rule that needs one asks the plan and
passes it to its job as a parameter (so that a changed fact reruns the job).

It reads no file but the measured datasets' ``metadata.yaml`` (when first asked) and
knows no Snakemake; making one is cheap (LAMMPS is imported when :attr:`RunPlan.lammps`
is first asked).
"""

from __future__ import annotations

import copy
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from chain.apparatus.virtual_settings import VirtualExperiment
from chain.labels import VIRTUAL_SERIES
from chain.physics.lammps_library import lammps_available
from chain.physics.model import ChainModel
from chain.pipeline.config.ablation import ablation_variants, variant_settings, variant_tolerance
from chain.pipeline.config.virtual import virtual_experiment_settings
from chain.pipeline.plan.datasets import ExperimentPart, experiment_label, experiment_parts
from chain.pipeline.plan.jobs import chain_of
from chain.pipeline.plan.resources import JobNeeds, simulation_needs, simulation_threads
from chain.studies.c_sensitivity import sensitivity_plan, shifted_pairs
from chain.studies.mechanism_settings import (
    CANDIDATE_REFERENCE,
    candidate_variants,
    sweep_settings,
    viscous_settings,
)

#: The contract tables of every run (tables/<name>.csv), in order.
TABLES = tuple("pulses delays delay_fits ssw ssw_fits ssw_track ssw_speed".split())

#: The figures of every run (figures/<name>.pdf and .png), in order; Fig. 2 follows
#: Fig. 1 when the run has an experiment, the optional figures come last.
FIGURES = tuple(
    "fig1_setup fig3_simulation_traces fig4_delay_vs_force fig5_ssw_vs_force ssw_spacetime".split()
)

#: The studies a config's ``studies`` switches on or off, in config order.
STUDIES = ("ablation", "c_sensitivity", "mechanisms")


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

    Attributes
    ----------
    run_name, out, tables, figures : str
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
    ablation : dict
        Variant name -> variant (:func:`chain.pipeline.config.ablation.ablation_variants`).
    """

    config: Mapping
    root: str = "."
    run_name: str = field(init=False)
    out: str = field(init=False)
    tables: str = field(init=False)
    figures: str = field(init=False)
    models: dict[str, float] = field(init=False)
    chains: dict[int, tuple[int, ...]] = field(init=False)
    long_chains: tuple[int, ...] = field(init=False)
    speeds: tuple[float, ...] = field(init=False)
    traces_n: tuple[int, ...] = field(init=False)
    ablation: dict[str, dict] = field(init=False)

    def __post_init__(self) -> None:
        config = copy.deepcopy(dict(self.config))
        out = f"results/{config['run_name']}"
        chains = {int(c["N"]): tuple(int(b) for b in c["sensors"]) for c in config["chains"]}
        derived = {
            "config": config,
            "run_name": config["run_name"],
            "out": out,
            "tables": f"{out}/tables",
            "figures": f"{out}/figures",
            "models": {m["name"]: m["eta_s"] for m in config["models"]},
            "chains": chains,
            "long_chains": tuple(int(n) for n in config["long_chains"]["N"]),
            "speeds": launch_speeds(config["launch"]),
            "traces_n": tuple(config["figures"]["traces_N"] or chains),
            "ablation": {v["name"]: v for v in ablation_variants(config)},
        }
        for name, value in derived.items():
            object.__setattr__(self, name, value)

    # ---- chains, durations, simulation jobs ----------------------------------------

    @property
    def tracked_chains(self) -> tuple[int, ...]:
        """Chains whose SSW is tracked contact by contact: the chains, then the long ones."""
        return (*self.chains, *self.long_chains)

    @property
    def field_chains(self) -> tuple[int, ...]:
        """Chains whose field the space-time figure shows: Fig. 3's chains, then the
        long ones."""
        return (*self.traces_n, *self.long_chains)

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
        """Every input that determines one simulate job's output (model, N), as a
        JSON-serialisable dict (:data:`chain.pipeline.plan.jobs.JOB_KEYS`; m, s, m/s): the
        chain, speeds, durations, step, record interval, readout. Analysis and figure
        keys are not in it; nor is a seed (the simulation draws nothing). A cache of
        results (issue 33) can hash it, with the job's code.

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

    @property
    def spacetime_model(self) -> str:
        """Model of the space-time figure: the first conservative model (where the SSW
        is a clean wave), or Fig. 3's model if none."""
        return (self.conservative or (self.config["figures"]["traces_model"],))[0]

    def simulation_needs(self, model: str, n_beads: int, threads: int) -> JobNeeds:
        """Memory (MB) and run time (minutes) a simulate job asks a scheduler for
        (:func:`chain.pipeline.plan.resources.simulation_needs`)."""
        job = self.simulate_job(model, n_beads)
        return simulation_needs(
            chain_of(job),
            len(self.speeds),
            max(self.speeds),
            job["duration_s"],
            job["record_interval_s"],
            job["time_step_s"],
            threads,
        )

    def simulation_threads(self, model: str, n_beads: int) -> int:
        """Cores a simulate job is worth (:func:`.resources.simulation_threads`)."""
        job = self.simulate_job(model, n_beads)
        return simulation_threads(
            chain_of(job), len(self.speeds), max(self.speeds), job["duration_s"], job["time_step_s"]
        )

    # ---- the experiment ---------------------------------------------------------------

    @cached_property
    def experiment(self) -> tuple[ExperimentPart, ...]:
        """The experiment's chains (:func:`chain.pipeline.plan.datasets.experiment_parts`;
        reads the measured datasets' metadata when first asked)."""
        return tuple(experiment_parts(self.config, root=self.root))

    @cached_property
    def experiment_label(self) -> str:
        """How figures and the summary name the experiment series."""
        return experiment_label(list(self.experiment))

    @property
    def virtual_run(self) -> bool:
        """Whether the experiment is the virtual experiment (``experiment.source``)."""
        return self.config["experiment"]["source"] == "virtual"

    @property
    def virtual_name(self) -> str:
        """Series name of the virtual experiment's datasets."""
        return self.config["experiment"]["name"] or VIRTUAL_SERIES

    def virtual_settings(self, n_beads: int) -> dict:
        """Every input of the virtual experiment of the chain of N beads: the fields of
        :class:`~chain.apparatus.virtual.VirtualExperiment` as plain values (JSON),
        ``experiment.virtual`` under its own names, the seed the run's + N."""
        return virtual_experiment_settings(self.config, int(n_beads), self.chains[int(n_beads)])

    def raw_dataset(self, n_beads: int) -> str:
        """Folder of the virtual experiment's dataset of the chain of N beads (the
        ``virtual_experiment`` job's output, in the measured-trace format)."""
        return f"{self.out}/experiment/raw/N{int(n_beads)}"

    def virtual_experiment(self, n_beads: int) -> VirtualExperiment:
        """The virtual experiment of the chain of N beads (:meth:`virtual_settings`)."""
        return VirtualExperiment(**self.virtual_settings(n_beads))

    # ---- the studies ------------------------------------------------------------------

    @cached_property
    def c_sensitivity(self) -> dict:
        """The C-sensitivity study's choices
        (:func:`chain.studies.c_sensitivity.sensitivity_plan`, the run's speeds)."""
        return sensitivity_plan(self.config, list(self.speeds))

    @cached_property
    def c_sensitivity_study(self) -> dict:
        """:attr:`c_sensitivity` without the main estimator: the study's job computes
        the table for every estimator as the headline one, so that a what-if choosing
        another main estimator reuses its simulations."""
        return {k: v for k, v in self.c_sensitivity.items() if k != "main_estimator"}

    def c_sensitivity_jobs(self) -> list[dict]:
        """The simulate jobs of the C-sensitivity study, per eta then chain: every bead
        of every sensor pair recorded (:meth:`simulate_job` inputs)."""
        plan = self.c_sensitivity
        jobs = []
        for eta in plan["eta_s"]:
            for n in plan["chains"]:
                pairs = [shifted_pairs(plan["chains"], s)[n] for s in [0, *plan["shifts"]]]
                beads = sorted({b for pair in pairs for b in pair})
                name = f"eta{eta * 1e6:.3g}us"
                jobs.append(self.simulate_job(name, n, eta_s=eta, sensors=beads))
        return jobs

    def study(self, name: str) -> bool:
        """Whether the run makes the study ``name`` (config ``studies.<name>``; one of
        :data:`STUDIES`)."""
        return bool(self.config["studies"][name])

    @property
    def studies_not_run(self) -> list[str]:
        """The studies the config switches off, in :data:`STUDIES` order."""
        return [name for name in STUDIES if not self.study(name)]

    def ablation_names(self, full: bool) -> list[str]:
        """Variants of tables/ablation_exponent.csv (the default run's: those with
        default_run that name no mechanism, not the candidates' reference; only with
        the virtual experiment and ``studies.ablation``), or with ``full`` of
        ablation_exponent_all.csv (all, whether the study is on or not: asked for)."""
        if full:
            return list(self.ablation)
        if not (self.virtual_run and self.study("ablation")):
            return []
        return [
            name
            for name, v in self.ablation.items()
            if v["default_run"] and not v["mechanism"] and name != CANDIDATE_REFERENCE
        ]

    def ablation_settings(self, name: str) -> list[list[dict]]:
        """Per replicate, the VirtualExperiment fields of every chain of one variant."""
        variant = self.ablation[name]
        return [
            [variant_settings(self.config, variant, n, list(s), k) for n, s in self.chains.items()]
            for k in range(variant["replicates"])
        ]

    def ablation_tolerance(self, name: str) -> float | None:
        """Acceptance tolerance of a variant; None keeps every collision shot."""
        return variant_tolerance(self.config, self.ablation[name])

    def ablation_datasets(self, name: str) -> list[list[str]]:
        """Per replicate of a variant, the run's virtual-experiment datasets (one folder
        per chain, :meth:`raw_dataset`) when that replicate's settings are the run's
        virtual experiment's for every chain (its shots are those files, byte for
        byte), else ``[]`` (the variant simulates its shots)."""
        run = [self.virtual_settings(n) for n in self.chains] if self.virtual_run else None
        return [
            [self.raw_dataset(n) for n in self.chains] if chains == run else []
            for chains in self.ablation_settings(name)
        ]

    @cached_property
    def ablation_twins(self) -> dict[str, str]:
        """Variant -> the first variant listed before it with the same settings (every
        replicate) and tolerance, whose outputs are therefore its own (copied, not
        computed again); only variants that have such a twin."""
        first: dict[str, str] = {}
        twins = {}
        for name in self.ablation:
            key = json.dumps([self.ablation_settings(name), self.ablation_tolerance(name)])
            if key in first:
                twins[name] = first[key]
            first.setdefault(key, name)
        return twins

    @cached_property
    def lammps(self) -> bool:
        """Whether the LAMMPS rules run: ``studies.mechanisms`` is on and LAMMPS imports."""
        return self.study("mechanisms") and lammps_available()

    def sweep(self, full: bool) -> dict[str, tuple[float, float]]:
        """Setting name -> (mu_t, mu_b) of the LAMMPS friction sweep (default run's or all)."""
        return sweep_settings(self.config, full=full)

    def viscous(self, full: bool) -> dict[str, float]:
        """Setting name -> gamma (N s/m) of the viscous inter-bead settings."""
        return viscous_settings(self.config, full=full)

    @property
    def frictionless(self) -> str:
        """Name of the sweep's frictionless reference setting."""  # always first
        return next(iter(self.sweep(full=False)))

    def candidates(self, full: bool) -> dict[str, tuple[str, str]]:
        """Variant -> (mechanism, setting) of the mechanism study's candidates (the
        virtual experiment's ablation variants with a mechanism); empty unless the
        experiment is virtual and ``studies.mechanisms`` on."""
        if not (self.virtual_run and self.study("mechanisms")):
            return {}
        return candidate_variants(list(self.ablation.values()), full)

    @property
    def mechanism_table(self) -> bool:
        """Whether tables/ssw_mechanisms.csv (and its figure) is made."""
        return self.lammps or bool(self.candidates(full=False))

    # ---- targets ----------------------------------------------------------------------

    def figure_names(self) -> list[str]:
        """The run's figures (contract names), in order."""
        figures = self.config["figures"]
        names = list(FIGURES)
        if self.experiment:
            names.insert(1, "fig2_experiment_traces")
        if self.study("c_sensitivity"):
            names.append("fig_c_sensitivity")
        if figures["parity_ssw_vs_N"]:
            names.append("fig_parity_ssw_vs_N")
        if figures["sweep_vs_N"]:
            names.append("fig_c_vs_N")
        if self.mechanism_table:
            names.append("fig_ssw_mechanisms")
        return names

    def optional_table(self, name: str) -> list[str]:
        """``[tables/<name>.csv]`` when the run makes that optional table, else ``[]``.

        Parameters
        ----------
        name : {"c_sensitivity", "ablation_exponent", "sweep", "lammps_check", "ssw_mechanisms"}
        """
        made = {
            "c_sensitivity": self.study("c_sensitivity"),
            "ablation_exponent": bool(self.ablation_names(full=False)),
            "sweep": bool(self.config["figures"]["sweep_vs_N"]),
            "lammps_check": self.lammps,
            "ssw_mechanisms": self.mechanism_table,
        }[name]
        return [f"{self.tables}/{name}.csv"] if made else []

    def targets(self) -> list[str]:
        """Every file of the default run (rule all), relative to the working directory."""
        out = self.out
        return (
            [f"{self.tables}/{table}.csv" for table in TABLES]
            + self.optional_table("c_sensitivity")
            + self.optional_table("ablation_exponent")
            + [f"{self.figures}/{n}.{ext}" for n in self.figure_names() for ext in ("pdf", "png")]
            + [f"{out}/summary.json", f"{out}/summary.md", f"{out}/article.pdf"]
            + self.optional_table("sweep")
            + self.optional_table("lammps_check")
            + self.optional_table("ssw_mechanisms")
        )
