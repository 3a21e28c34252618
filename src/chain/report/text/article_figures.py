"""Where each figure of a run sits in the article, its caption and, for the supplementary
figures, the paragraph that discusses it, with the run's numbers.

article.typ places a section's figures with ``#figures-in("<section>")``; the section of
each figure is :data:`FIGURE_SECTIONS`. A figure this module does not know goes to the
section ``supplementary`` with a generic caption and paragraph, so no figure is left
without a text and no section without a figure's discussion. Adding a figure is one
entry in :data:`FIGURE_SECTIONS` and :data:`CAPTIONS` (and a paragraph function in
:data:`PARAGRAPHS` if the section's own text does not discuss it).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping

from chain.report.naming import named
from chain.report.printed import plus_minus, power_of_ten

#: The section of the article that discusses each figure.
FIGURE_SECTIONS = {
    "fig1_setup": "method",
    "fig2_experiment_traces": "claims",
    "fig3_simulation_traces": "claims",
    "fig4_delay_vs_force": "ballistic",
    "fig_c_sensitivity": "choices",
    "fig_c_vs_N": "choices",
    "fig5_ssw_vs_force": "ssw",
    "ssw_spacetime": "ssw",
    "fig_parity_ssw_vs_N": "ssw",
    "fig_ssw_mechanisms": "mechanisms",
}

#: What to see in each figure (the article's own words); numbers are added by
#: :func:`caption`.
CAPTIONS = {
    "fig1_setup": "The chain as configured for this run: beads, strikers, the two sensor "
    "beads S1 and S2, and the left- and right-travelling waves (LSTW, RSTW).",
    "fig2_experiment_traces": "Force at the two sensors in the experiment series of this "
    "run, one column per chain: the left-launched wave solid, the right-launched dashed, "
    "a reference wave that crossed nothing dotted: compare the arrival of the crossed "
    "waves with the reference's.",
    "fig3_simulation_traces": "The same from the simulation of Eq. 1, force felt by the "
    "sensor beads (sensors not modelled), with the SSW marked where it is found.",
    "fig4_delay_vs_force": "|Δ| against the incident amplitude F_m at the first sensor, "
    "log-log: simulations, experiment series, the fits C F_m^(−1/6), the two ballistic "
    "estimates, and the paper's C_exp quoted; a line of slope −1/6 is the scaling the "
    "paper claims.",
    "fig5_ssw_vs_force": "(a) Amplitude of the secondary solitary wave against the "
    "incident amplitude at the sensors, per series and chain: error bars template misfit "
    "and noise, filled resolved, arrows upper limits, lines the proportional fits. "
    "(b) SSW / F_m against distance from the collision point where it has separated, "
    "long chains included.",
    "ssw_spacetime": "Contact force over contact index and time for one collision in an "
    "odd and an even chain, the paper's and long ones (log colour scale), with the tracked "
    "waves; beside it, the SSW amplitude against distance from the collision point.",
    "fig_parity_ssw_vs_N": "SSW slope against the number of beads, odd and even chains.",
    "fig_c_sensitivity": "C, chains pooled, for each choice of estimator, dissipation η, "
    "sensor pair and amplitude range, one choice changed at a time from the headline.",
    "fig_c_vs_N": "C against the number of beads N of the chain, per model.",
    "fig_ssw_mechanisms": "SSW amplitude over F_m at S2 (models, not data) for each "
    "candidate mechanism and setting, N = 25 and N = 26: LAMMPS with track and bead "
    "friction and rotation, or a viscous inter-bead force, against the frictionless "
    "chain; the virtual experiment's candidates against it as configured. Dashes: the "
    "reference; dotted: twice it, the mark of significantly larger; n/r: no value.",
}

UNITS_C = "µs N^1/6"


def _pooled_c(summary: Mapping) -> str:
    """'simulation, elastic 43.23 ± 0.24; virtual experiment (model) 42.9 ± 0.5'."""
    rows = [
        r
        for r in summary.get("delay_fits") or []
        if r["N"] == "pooled" and r["estimator"] == summary.get("main_estimator")
    ]
    return "; ".join(
        f"{named(summary, r['source'], r['model'])} "
        f"{plus_minus(r.get('C_us_N16'), r.get('C_stderr_us_N16'))}"
        for r in rows
    )


def _slopes(summary: Mapping) -> str:
    """'simulation, elastic, N = 25: 0.0123 ± 0.0004; ...' of the SSW fits that gave a
    slope ('' for none)."""
    return "; ".join(
        f"{named(summary, r['source'], r['model'])}, N = {r['N']}: "
        f"{plus_minus(r.get('slope'), r.get('slope_stderr'))}"
        for r in summary.get("ssw_fits") or []
        if r.get("slope") is not None and math.isfinite(float(r["slope"]))
    )


def _numbers_fig4(summary: Mapping) -> str:
    constants, paper = summary["constants"], summary["paper"]
    return (
        f"Pooled C ({UNITS_C}): {_pooled_c(summary)}; ballistic "
        f"{constants['C_bal_paper_us_N16']:.2f} (Eq. 6) and "
        f"{constants['C_bal_exact_us_N16']:.2f} (exact contact time); paper "
        f"C_exp = {plus_minus(paper['C_exp_us_N16'], paper['C_exp_err_us_N16'])}."
    )


def _numbers_spread(summary: Mapping) -> str | None:
    spread = summary.get("c_spread")
    if not spread:
        return None
    return (
        f"C runs from {spread['min_us_N16']:.2f} to {spread['max_us_N16']:.2f} {UNITS_C} "
        "over the choices."
    )


def _numbers_slopes(summary: Mapping) -> str:
    slopes = _slopes(summary)
    return f"Fitted slopes SSW / F_m: {slopes}." if slopes else "No series gave a slope."


def _numbers_drift(summary: Mapping) -> str | None:
    drift = summary.get("max_energy_drift")
    return None if drift is None else f"Largest relative energy drift {power_of_ten(drift)}."


def _numbers_chains(summary: Mapping) -> str | None:
    chains = sorted({int(r["N"]) for r in summary.get("delay_fits") or [] if r["N"] != "pooled"})
    return f"Chains of N = {', '.join(map(str, chains))} beads." if chains else None


def _numbers_selection(summary: Mapping) -> str | None:
    """'Kept by the acceptance rule: N = 25, 17 of 24 collisions; ...'."""
    parts = [
        f"N = {c['N']}, {c['kept']} of {c['kept'] + c['rejected']} {c['kind']}s"
        for c in summary.get("selection") or []
        if c.get("kind") == "collision"
    ]
    return f"Kept by the acceptance rule: {'; '.join(parts)}." if parts else None


def _numbers_separation(summary: Mapping) -> str | None:
    rows = summary.get("ssw_separation") or []
    shots = sum(int(r.get("n_shots") or 0) for r in rows)
    separated = sum(int(r.get("n_shots_separated") or 0) for r in rows)
    return f"The SSW separated in {separated} of {shots} tracked waves." if shots else None


#: Numbers each caption adds, from summary.json (None: the caption alone).
_CAPTION_NUMBERS: dict[str, Callable[[Mapping], str | None]] = {
    "fig1_setup": _numbers_chains,
    "fig2_experiment_traces": _numbers_selection,
    "ssw_spacetime": _numbers_separation,
    "fig3_simulation_traces": _numbers_drift,
    "fig4_delay_vs_force": _numbers_fig4,
    "fig5_ssw_vs_force": _numbers_slopes,
    "fig_parity_ssw_vs_N": _numbers_slopes,
    "fig_c_sensitivity": _numbers_spread,
}


def caption(name: str, summary: Mapping) -> str:
    """The caption of figure ``name``: what to see, then the run's numbers."""
    text = CAPTIONS.get(name, f"Figure {name.replace('_', ' ')} of this run.")
    numbers = _CAPTION_NUMBERS.get(name, lambda _: None)(summary)
    return f"{text} {numbers}" if numbers else text


def _paragraph_sensitivity(summary: Mapping) -> str:
    spread = summary.get("c_spread") or {}
    ranges: dict[str, list[float]] = {}
    for row in spread.get("rows") or []:
        if str(row.get("N")) == "pooled" and row.get("C") is not None and not row.get("note"):
            ranges.setdefault(str(row["choice"]), []).append(float(row["C"]))
    if not ranges:
        return "shows how C moves when one choice of the analysis changes."
    widths = sorted(((max(v) - min(v), k) for k, v in ranges.items()), reverse=True)
    names = {"eta_us": "η", "amplitudes": "the amplitude range", "sensors": "the sensor pair"}
    moves = ", ".join(f"{names.get(k, k)} by {w:.1f}" for w, k in widths)
    return (
        "sets the choices side by side. Changed one at a time, they move the pooled C "
        f"({UNITS_C}) as follows: {moves}; over all choices C spans "
        f"{spread['min_us_N16']:.2f} to {spread['max_us_N16']:.2f} (every row in the "
        "appendix)."
    )


def _paragraph_spacetime(summary: Mapping) -> str:
    rows = summary.get("ssw_separation") or []
    separated = sum(int(r.get("n_shots_separated") or 0) for r in rows)
    shots = sum(int(r.get("n_shots") or 0) for r in rows)
    counted = (
        f" In the simulated collisions the SSW separated from the crossed pulse in "
        f"{separated} of {shots} tracked waves."
        if shots
        else ""
    )
    return (
        "follows one collision through the chain: the two main waves cross, and the "
        "SSW trails each of them; its amplitude against distance shows where it has "
        f"separated, which decides whether a sensor can resolve it.{counted}"
    )


def _paragraph_slopes(summary: Mapping) -> str:
    slopes = _slopes(summary)
    return (
        "sets the SSW slope of each chain against N, odd and even chains apart, to see "
        "whether even chains (waves meeting at a contact) leave the larger SSW"
        + (f"; the slopes: {slopes}." if slopes else ".")
    )


def _paragraph_ssw(summary: Mapping) -> str:
    rows = summary.get("ssw_fits") or []
    slopes = _slopes(summary)
    if slopes:
        return (
            "sets the SSW amplitude against the incident amplitude for every series and "
            "chain, each point with its error (template misfit and noise) or as an upper "
            f"limit; the proportional fits of every point give SSW / F_m = {slopes}."
        )
    return (
        "sets the SSW amplitude against the incident amplitude for every series and "
        f"chain. In this run none of the {len(rows)} series resolved an SSW at its "
        "sensors: the figure says so, and no slope is fitted."
    )


#: The paragraph that discusses a supplementary figure (its section's text does not).
PARAGRAPHS: dict[str, Callable[[Mapping], str]] = {
    "fig_c_sensitivity": _paragraph_sensitivity,
    "fig_c_vs_N": lambda _: (
        "repeats the fit of C for chains of other lengths. Eq. 6 holds no N, so "
        "the ballistic picture expects the same C for every chain long enough for the waves "
        "to have formed before they meet."
    ),
    "fig5_ssw_vs_force": _paragraph_ssw,
    "ssw_spacetime": _paragraph_spacetime,
    "fig_parity_ssw_vs_N": _paragraph_slopes,
}


def figure_text(name: str, summary: Mapping) -> dict:
    """``{"section", "caption", "paragraph"}`` of figure ``name`` (file stem) for the
    run ``summary``; ``paragraph`` is None where the section's text discusses it."""
    known = name in FIGURE_SECTIONS
    paragraph = PARAGRAPHS.get(name)
    return {
        "section": FIGURE_SECTIONS.get(name, "supplementary"),
        "caption": caption(name, summary),
        "paragraph": paragraph(summary)
        if paragraph
        else None
        if known
        else "is a figure of this run that the article's text does not discuss yet; "
        "the caption says what it shows.",
    }
