"""The paper's claims beside this run's numbers, with a verdict computed from them.

:func:`claims` gives the article's claim-by-claim table (claim | paper | ours | agrees |
why not). A verdict is never typed: it compares our number with the paper's against the
tolerances of :data:`chain.report.numbers.claim_rows.TOLERANCES`, and says "not
testable" where this run has nothing to compare (no measurements). The paper's numbers
come from ``summary["paper"]`` (:mod:`chain.report.numbers.paper`), quoted as printed.

Every verdict is decided here, once, and written to ``summary.json`` (key ``verdicts``:
the tolerances, the dissipation ratios of :func:`dissipation_verdicts` and the claim
table of :func:`with_claims`); summary.md and the article read them. The SSW claims are
:mod:`chain.report.numbers.ssw_claims`.
"""

from __future__ import annotations

from collections.abc import Mapping

import pandas as pd

from chain.analysis.rows import is_ok
from chain.report.naming import is_virtual, named
from chain.report.numbers.claim_rows import (
    NOT_COMPUTED,
    TOLERANCES,
    claim_row,
    fit_row,
    loss_text,
    series_models,
)
from chain.report.numbers.mechanisms import friction_c_text
from chain.report.numbers.paper import PAPER_ENERGY_DRIFT
from chain.report.numbers.ssw_claims import ssw_claims
from chain.report.printed import percent, plus_minus, power_of_ten


def _early_claim(summary, delays: pd.DataFrame | None) -> list[dict]:
    """Crossed waves arrive early: the sign of every usable Δ of the main estimator."""
    if delays is None or not len(delays):
        return [claim_row("Crossed waves come out early", "Δ ≠ 0 (Fig. 2)", NOT_COMPUTED, None)]
    rows = delays[(delays["estimator"] == summary["main_estimator"]) & is_ok(delays)]
    rows = rows[rows["delay_us"].notna()]
    parts, ok = [], True
    for (source, model), group in rows.groupby(["source", "model"], sort=False):
        early = int((group["delay_us"] < 0).sum())
        parts.append(f"{named(summary, source, model)}: {early} of {len(group)}")
        ok = ok and early == len(group)
    return [
        claim_row(
            "Crossed waves come out early (a phase shift)",
            "shift seen, no count printed",
            "waves early: " + "; ".join(parts) if parts else NOT_COMPUTED,
            ok if parts else None,
            "" if ok else "some crossed waves are not early",
        )
    ]


def _exponent_claims(summary) -> list[dict]:
    """|Δ| ∝ F_m^(−1/6): the free exponent of each series, chains pooled."""
    tolerance = TOLERANCES["delay_exponent"]
    ablation = summary.get("ablation") or {}
    out = []
    for source in ("simulation", "experiment"):
        for model in series_models(summary, source):
            row = fit_row(summary, source, model, "pooled")
            if row is None or row.get("exponent") is None:
                continue
            ok = abs(row["exponent"] + 1 / 6) <= tolerance
            why = ""
            if not ok and source == "simulation":
                why = loss_text(summary, model) or "dissipation; attenuation not computed"
            elif not ok:
                why = ablation.get("verdict") or f"cause {NOT_COMPUTED} (no ablation)"
            out.append(
                claim_row(
                    f"|Δ| ∝ F_m^(−1/6), {named(summary, source, model)}",
                    "−1/6 (Eq. 6; fits fix it)",
                    "free exponent " + plus_minus(row["exponent"], row["exponent_stderr"], 4),
                    ok,
                    why,
                )
            )
    return out


def _ballistic_claims(summary) -> list[dict]:
    """C_bal of Eq. 6 recomputed, and the same argument with the exact contact time."""
    printed = summary["paper"]["C_bal_us_N16"]
    ours = summary["constants"]["C_bal_paper_us_N16"]
    exact = summary["constants"]["C_bal_exact_us_N16"]
    recomputed_ok = abs(ours / printed - 1) <= TOLERANCES["C_bal_recomputed"]
    exact_ok = abs(exact / printed - 1) <= TOLERANCES["C"]
    return [
        claim_row(
            "Eq. 6 evaluated for the paper's beads",
            f"C_bal = {printed:.2f}",
            f"{ours:.2f} ({percent(ours, printed, 2)})",
            recomputed_ok,
            "" if recomputed_ok else "the bead data do not give the printed value",
        ),
        claim_row(
            "Eq. 6 is the ballistic collision-time difference",
            f"C_bal = {printed:.2f}",
            f"{exact:.2f} with the exact Hertz contact time ({percent(exact, printed)})",
            exact_ok,
            ""
            if exact_ok
            else "Eq. 6 takes the contact time of a bead hitting an immovable "
            "body (mass m); two free beads collide with the reduced mass m/2",
        ),
    ]


def _c_claims(summary) -> list[dict]:
    """The measured C_exp against our experiment series and our simulations."""
    paper = summary["paper"]
    c_exp, err = paper["C_exp_us_N16"], paper["C_exp_err_us_N16"]
    tolerance = TOLERANCES["C"]
    virtual = is_virtual(summary.get("experiment_label", "experiment"))
    out = []
    for source in ("experiment", "simulation"):
        for model in series_models(summary, source):
            row = fit_row(summary, source, model, "pooled")
            if row is None or row.get("C_us_N16") is None:
                continue
            c = row["C_us_N16"]
            ok = abs(c / c_exp - 1) <= tolerance
            if source == "experiment":
                claim = "C_exp, fit of the measured |Δ|"
                why = (
                    "a model of the apparatus, not the paper's measurements"
                    if virtual
                    else "a different set of measurements"
                )
            else:
                claim = "Simulations of Eq. 1 close to the measured Δ"
                why = _simulation_c_why(summary)
            out.append(
                claim_row(
                    f"{claim} ({named(summary, source, model)})",
                    f"C_exp = {c_exp:.1f} ± {err:.1f}",
                    f"C = {plus_minus(c, row['C_stderr_us_N16'], 2)} ({percent(c, c_exp)})",
                    ok,
                    "" if ok else why,
                )
            )
    return out


def _simulation_c_why(summary) -> str:
    """Why a simulated C is not the measured one: the mechanism study's answer when the
    run has it (track friction and bead rotation modelled, C with and without), else
    the paper's explanation, which this run does not test."""
    moved = friction_c_text(summary.get("ssw_mechanisms"))
    if moved is None:
        return "no track friction or bead rotation modelled (the paper's explanation)"
    return (
        "Eq. 1 has no track friction or bead rotation (the paper's explanation); the "
        f"mechanism study models both: {moved}"
    )


def dissipation_pairs(summary):
    """(model, base, fit, base fit): each dissipative model's pooled main fit beside each
    conservative model's."""
    conservative = summary.get("conservative_models") or []
    for base in conservative:
        reference = fit_row(summary, "simulation", base, "pooled")
        for model in series_models(summary, "simulation"):
            row = fit_row(summary, "simulation", model, "pooled")
            if model in conservative or reference is None or row is None:
                continue
            if row.get("C_us_N16") is None or reference.get("C_us_N16") is None:
                continue
            yield model, base, row, reference


def dissipation_verdicts(summary) -> list[dict]:
    """C of each dissipative model over C of each conservative one (chains pooled, main
    estimator), and whether the ratio is 1 within ``TOLERANCES["dissipation_ratio"]``:
    the paper's "dissipation does not change Δ" (Sec. V), decided here only. One
    ``{model, base, ratio, agrees}`` per pair of :func:`dissipation_pairs`."""
    out = []
    for model, base, row, reference in dissipation_pairs(summary):
        ratio = row["C_us_N16"] / reference["C_us_N16"]
        ok = abs(ratio - 1) <= TOLERANCES["dissipation_ratio"]
        out.append({"model": model, "base": base, "ratio": ratio, "agrees": ok})
    return out


def _dissipation_claim(summary) -> list[dict]:
    """Δ independent of viscoelastic dissipation: C(dissipative) / C(conservative)."""
    verdicts = (summary.get("verdicts") or {}).get("dissipation")
    if verdicts is None:
        verdicts = dissipation_verdicts(summary)
    return [
        claim_row(
            "Viscoelastic dissipation does not change Δ",
            "C unchanged (Sec. V)",
            f"C({v['model']}) / C({v['base']}) = {v['ratio']:.3f}",
            v["agrees"],
            "" if v["agrees"] else (loss_text(summary, v["model"]) or ""),
        )
        for v in verdicts
    ]


def energy_drift_within_paper(drift: float | None) -> bool | None:
    """Whether the conservative runs' largest relative energy drift is within the
    paper's order (:data:`PAPER_ENERGY_DRIFT`, Sec. II); None without any."""
    return None if drift is None else bool(drift <= PAPER_ENERGY_DRIFT)


def _drift_claim(summary) -> list[dict]:
    drift = summary.get("max_energy_drift")
    ok = energy_drift_within_paper(drift)
    return [
        claim_row(
            "Energy conserved by the integrator (conservative chain)",
            f"~{power_of_ten(PAPER_ENERGY_DRIFT, 1)}",
            NOT_COMPUTED if drift is None else power_of_ten(drift),
            ok,
            "" if ok in (None, True) else "larger drift",
        )
    ]


def claims(summary: Mapping, delays=None, ssw=None) -> list[dict]:
    """The claim-by-claim table, rows of ``claim``, ``paper`` (the paper's number or
    statement), ``ours``, ``agrees`` ("yes", "no" or "not testable", against
    :data:`chain.report.numbers.claim_rows.TOLERANCES`) and ``why`` (not).

    Parameters
    ----------
    summary : mapping
        The run's ``summary.json``.
    delays, ssw : DataFrame, optional
        ``delays.csv`` (the sign of Δ) and ``ssw.csv`` (the SSW exponent against F_m).
    """
    return [
        *_early_claim(summary, delays),
        *_exponent_claims(summary),
        *_ballistic_claims(summary),
        *_c_claims(summary),
        *_dissipation_claim(summary),
        *ssw_claims(summary, ssw),
        *_drift_claim(summary),
    ]


def with_claims(summary: Mapping, delays=None, ssw=None) -> dict:
    """``summary`` with its claim table decided: ``verdicts["claims"]`` is
    :func:`claims` of it. Called last, when the summary holds the studies (ablation,
    mechanisms) whose findings answer a claim's "why not".

    Parameters
    ----------
    summary : mapping
        The run's ``summary.json`` contents (``build_summary`` of
        :mod:`chain.report.numbers.summary`, and the study entries).
    delays, ssw : DataFrame, optional
        ``delays.csv`` and ``ssw.csv``.
    """
    verdicts = dict(summary.get("verdicts") or {})
    verdicts["claims"] = claims(summary, delays, ssw)
    return {**summary, "verdicts": verdicts}
