"""The figures of a run: one registry that the rules, the HTML report and the article
read.

Each figure is one entry of :data:`FIGURES`: the files it reads, its parameters and
when the run draws it. From the entry the plan makes its rule (script
``workflow/scripts/<name>.py``, outputs ``figures/<name>.pdf`` and ``.png``, log
``logs/figures/<name>.log``); the PNG goes to the HTML report with the caption
``workflow/report/<name>.rst`` if there is one, else a generic one; the article embeds
every figure of the run in :meth:`FigurePlan.names` order, and
:mod:`chain.report.text.article_figures` gives its section and caption (a supplementary
section and a generic caption when it has none). A new figure is a module in
``chain/report/figures``, its script and its entry here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from chain.pipeline.plan.steps import Part, Step


@dataclass(frozen=True)
class Figure:
    """One figure of the registry.

    Attributes
    ----------
    name : str
        Contract name (file stem, rule and script name).
    inputs : callable
        The run's plan -> named inputs (paths).
    params : callable
        The run's plan -> parameters.
    when : callable
        The run's plan -> whether the run draws it.
    priority, threads : int
        Snakemake priority and cores of its job.
    """

    name: str
    inputs: Callable = lambda plan: {}
    params: Callable = lambda plan: {}
    when: Callable = lambda plan: True
    priority: int = 0
    threads: int = 1


def _estimator(plan) -> str:
    return plan.config["analysis"]["main_estimator"]


def _figures_key(plan, key: str):
    return plan.config["figures"][key]


def _traces_inputs(plan, traces: list[str]) -> dict:
    t = plan.analysis.table
    return {"traces": traces, "pulses": t("pulses"), "ssw": t("ssw")}


def _fields(plan, chains) -> list[str]:
    sim = plan.simulation
    return [sim.file(sim.spacetime_model, n, "field") for n in chains]


#: Every figure, in the order the run lists them.
FIGURES = (
    Figure(
        "fig1_setup",
        params=lambda plan: {
            "chains": plan.config["chains"], "radius_m": plan.config["radius_m"],
            "material": plan.config["material"],
            "striker_radius_m": plan.config["setup"]["striker_radius_m"],
        },
    ),
    Figure(
        "fig2_experiment_traces",
        inputs=lambda plan: {
            **_traces_inputs(plan, plan.experiment.trace_files(
                tuple(_figures_key(plan, "traces_N") or ()))),
            "selection": plan.experiment.selection_files(),
        },
        params=lambda plan: {
            "representative_force_N": _figures_key(plan, "experiment_force_N")
            or _figures_key(plan, "representative_force_N"),
            "estimator": _estimator(plan), "label": plan.experiment.label,
        },
        when=lambda plan: bool(plan.experiment.chains),
    ),
    Figure(
        "fig3_simulation_traces",
        inputs=lambda plan: _traces_inputs(plan, [
            plan.simulation.file(_figures_key(plan, "traces_model"), n, "traces")
            for n in plan.traces_n
        ]),
        params=lambda plan: {
            "model": _figures_key(plan, "traces_model"),
            "representative_force_N": _figures_key(plan, "representative_force_N"),
            "representative_index": _figures_key(plan, "representative_index"),
            "estimator": _estimator(plan), "label": "simulation",
        },
    ),
    Figure(
        "fig4_delay_vs_force",
        inputs=lambda plan: {"delays": plan.analysis.table("delays"),
                             "fits": plan.analysis.table("delay_fits")},
        params=lambda plan: {
            "material": plan.config["material"], "radius_m": plan.config["radius_m"],
            "estimator": _estimator(plan), "experiment_label": plan.experiment.label,
        },
    ),
    # At the end of the longest chain of tables: started before shorter figures.
    Figure(
        "fig5_ssw_vs_force",
        inputs=lambda plan: {
            name: plan.analysis.table(table) for name, table in
            (("ssw", "ssw"), ("fits", "ssw_fits"), ("track", "ssw_track"), ("speed", "ssw_speed"))
        },
        params=lambda plan: {
            "experiment_label": plan.experiment.label,
            "sensors": {n: list(s) for n, s in plan.chains.items()},
        },
        priority=1,
    ),
    # The longest figure: started as soon as its inputs exist. PDF and PNG are drawn
    # at once, in two processes on a cluster (a local run gives it one core:
    # profiles/default).
    Figure(
        "ssw_spacetime",
        inputs=lambda plan: {
            "fields": _fields(plan, plan.traces_n),
            "long_fields": _fields(plan, plan.long_chains),
            "track": plan.analysis.table("ssw_track"),
        },
        params=lambda plan: {
            "model": plan.simulation.spacetime_model, "chains": list(plan.traces_n),
            "long_chains": list(plan.long_chains),
        },
        priority=1, threads=2,
    ),
    Figure(
        "fig_c_sensitivity",
        inputs=lambda plan: {"table": plan.analysis.table("c_sensitivity")},
        when=lambda plan: plan.study("c_sensitivity"),
    ),
    Figure(
        "fig_parity_ssw_vs_N",
        inputs=lambda plan: {"fits": plan.analysis.table("ssw_fits")},
        params=lambda plan: {"experiment_label": plan.experiment.label},
        when=lambda plan: bool(_figures_key(plan, "parity_ssw_vs_N")),
    ),
    Figure(
        "fig_c_vs_N",
        inputs=lambda plan: {"sweep": plan.analysis.table("sweep")},
        when=lambda plan: bool(_figures_key(plan, "sweep_vs_N")),
    ),
    Figure(
        "fig_ssw_mechanisms",
        inputs=lambda plan: {"table": plan.analysis.table("ssw_mechanisms")},
        when=lambda plan: plan.mechanisms.table_made,
    ),
)  # fmt: skip


class FigurePlan(Part):
    """The figures a run draws (:data:`FIGURES`), as steps."""

    def names(self) -> list[str]:
        """The run's figures (contract names), in order."""
        return [figure.name for figure in FIGURES if figure.when(self.plan)]

    def files(self, name: str) -> list[str]:
        """The PDF and PNG of figure ``name``."""
        return [f"{self.plan.figures_dir}/{name}.{ext}" for ext in ("pdf", "png")]

    def steps(self) -> list[Step]:
        """One step per figure the run draws."""
        plan = self.plan
        return [
            Step(
                figure.name,
                dict(zip(("pdf", "png"), self.files(figure.name), strict=True)),
                inputs=lambda w, f=figure: f.inputs(plan),
                params=lambda w, f=figure: f.params(plan),
                log=f"{plan.out}/logs/figures/{figure.name}.log",
                report={"png": (f"{figure.name}.rst", "Figures")},
                priority=figure.priority,
                threads=figure.threads,
            )
            for figure in FIGURES
            if figure.when(plan)
        ]

    def targets(self) -> list[str]:
        """Every figure's PDF and PNG."""
        return [path for name in self.names() for path in self.files(name)]
