"""The paper's claims beside this run's numbers, with a verdict computed from them.

:func:`claims` gives the article's claim-by-claim table (claim | paper | ours | agrees |
why not). A verdict is never typed: it compares our number with the paper's against the
tolerances of :data:`TOLERANCES`, and says "not testable" where this run has nothing to
compare (no measurements). The paper's numbers come from ``summary["paper"]``
(:mod:`chain.report.numbers.paper`), quoted as printed.

Every verdict is decided here, once, and written to ``summary.json`` (key ``verdicts``:
the tolerances, the dissipation ratios of :func:`dissipation_verdicts` and the claim
table of :func:`with_claims`); summary.md and the article read them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import pandas as pd

from chain.analysis.regression import fit_power_law, ratio_with_error
from chain.analysis.rows import is_ok
from chain.labels import VIRTUAL_LABEL
from chain.report.naming import is_virtual, named
from chain.report.numbers.mechanisms import friction_c_text
from chain.report.numbers.paper import PAPER_ENERGY_DRIFT
from chain.report.printed import (
    fixed,
    number,
    percent,
    plus_minus,
    plus_minus_stat_sys,
    power_of_ten,
)

#: When a number of ours "agrees" with the paper's claim. Relative for C, absolute for
#: exponents; printed in the article beside the table.
TOLERANCES = {
    # C_bal of Eq. 6 recomputed from the paper's bead data against the printed value:
    # only rounding of rho, Y, nu can separate them.
    "C_bal_recomputed": 0.001,
    # Any C against the paper's: 5 %, ten times the paper's stated error of C_exp (1 %).
    "C": 0.05,
    # Free exponent of |Delta| against -1/6 (the paper's fits fix it).
    "delay_exponent": 0.01,
    # C(dissipative) / C(conservative) against 1 (the summary's 2 %).
    "dissipation_ratio": 0.02,
    # Free exponent of SSW amplitude against F_m, against 1 (proportional).
    "ssw_exponent": 0.05,
}

#: What the article prints where a finding was not computed by this run.
NOT_COMPUTED = "not computed in this run"


def fit_row(summary, source, model, n, estimator=None) -> dict | None:
    """The ``delay_fits`` row of a series, or None.

    Parameters
    ----------
    summary : mapping
        The run's ``summary.json``.
    source, model : str
        The series (``simulation``/``experiment`` and the model or dataset name).
    n : int or "pooled"
        The chain, or the fit with the chains pooled.
    estimator : str, optional
        The pulse estimator; the run's main one by default.
    """
    wanted = (source, model, n, estimator or summary["main_estimator"])
    for row in summary["delay_fits"]:
        if (row["source"], row["model"], row["N"], row["estimator"]) == wanted:
            return row
    return None


def series_models(summary, source) -> list[str]:
    """Models of ``source`` in the delay fits, in order of appearance."""
    return list(dict.fromkeys(r["model"] for r in summary["delay_fits"] if r["source"] == source))


def _verdict(ok: bool | None) -> str:
    return "not testable" if ok is None else ("yes" if ok else "no")


def _claim(claim, paper, ours, ok, why="") -> dict:
    return {"claim": claim, "paper": paper, "ours": ours, "agrees": _verdict(ok), "why": why}


def loss_text(summary, model) -> str | None:
    """'a lone wave loses 4.0 % (at 9.5 N) to 8.0 % (at 927 N) between the sensors'."""
    rows = [r for r in summary.get("attenuation") or [] if r["model"] == model]
    if not rows:
        return None
    row = max(rows, key=lambda r: 1 - r["ratio_high"])
    return (
        f"a lone wave loses {100 * (1 - row['ratio_low']):.1f} % (at "
        f"{number(row['F_S1_low_N'], 3)} N) to {100 * (1 - row['ratio_high']):.1f} % (at "
        f"{number(row['F_S1_high_N'], 3)} N) of its "
        f"amplitude between S1 and S2 (N = {row['N']}), so the waves cross weaker than the "
        "F_m measured at S1, by a fraction that grows with F_m"
    )


def _early_claim(summary, delays: pd.DataFrame | None) -> list[dict]:
    """Crossed waves arrive early: the sign of every usable Δ of the main estimator."""
    if delays is None or not len(delays):
        return [_claim("Crossed waves come out early", "Δ ≠ 0 (Fig. 2)", NOT_COMPUTED, None)]
    rows = delays[(delays["estimator"] == summary["main_estimator"]) & is_ok(delays)]
    rows = rows[rows["delay_us"].notna()]
    parts, ok = [], True
    for (source, model), group in rows.groupby(["source", "model"], sort=False):
        early = int((group["delay_us"] < 0).sum())
        parts.append(f"{named(summary, source, model)}: {early} of {len(group)}")
        ok = ok and early == len(group)
    return [
        _claim(
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
                _claim(
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
        _claim(
            "Eq. 6 evaluated for the paper's beads",
            f"C_bal = {printed:.2f}",
            f"{ours:.2f} ({percent(ours, printed, 2)})",
            recomputed_ok,
            "" if recomputed_ok else "the bead data do not give the printed value",
        ),
        _claim(
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
                _claim(
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
    the paper's "dissipation does not change Δ" (Sec. V), decided here only.

    Returns
    -------
    list of dict
        ``model``, ``base`` (the conservative model), ``ratio`` (C / C_base) and
        ``agrees`` (bool), per pair of :func:`dissipation_pairs`.
    """
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
        _claim(
            "Viscoelastic dissipation does not change Δ",
            "C unchanged (Sec. V)",
            f"C({v['model']}) / C({v['base']}) = {v['ratio']:.3f}",
            v["agrees"],
            "" if v["agrees"] else (loss_text(summary, v["model"]) or ""),
        )
        for v in verdicts
    ]


def _ssw_rows(ssw: pd.DataFrame | None) -> pd.DataFrame:
    """The measurable rows of the SSW measurement fitted (``residual``)."""
    if ssw is None or not len(ssw):
        return pd.DataFrame(columns=["source", "model", "N", "F_m_N", "ssw_N"])
    rows = ssw[is_ok(ssw)]
    if "method" in rows.columns:
        rows = rows[rows["method"] == "residual"]
    return rows


def _ssw_fit_rows(summary) -> dict:
    """``{(source, model, N): ssw_fits row}`` of the per-chain residual fits."""
    return {
        (r["source"], r["model"], r["N"]): r
        for r in summary.get("ssw_fits") or []
        if r.get("method", "residual") == "residual" and r["N"] != "pooled"
    }


def _stat(fit) -> float:
    """A fit's statistical error (its total error in tables without the split)."""
    return fit.get("slope_stat", fit.get("slope_stderr"))


def _pct(fit) -> str:
    """'(3.4 ± < 0.1 (stat) ± 2.1 (sys)) % of F_m' (:mod:`chain.report.printed`)."""
    if fit.get("slope_sys") is None:
        return f"({plus_minus(100 * fit['slope'], 100 * _stat(fit))}) % of F_m"
    parts = (100 * fit["slope"], 100 * _stat(fit), 100 * fit["slope_sys"])
    return f"({plus_minus_stat_sys(*parts)}) % of F_m"


def _proportional_claim(summary, source, model, group, fits) -> dict:
    """SSW ∝ F_m for one series: slope, scatter of SSW / F_m, free exponent per chain."""
    parts, tested, ok = [], 0, True
    for n, rows in group.groupby("N", sort=True):
        fit = fits.get((source, model, int(n)))
        ratio = rows["ssw_N"] / rows["F_m_N"]
        above = rows[~rows["upper_limit"].astype(bool)] if "upper_limit" in rows else rows
        text = f"N = {n}: {_pct(fit) if fit else 'no fit'}, scatter of SSW/F_m "
        text += f"{fixed(100 * ratio.std() / ratio.mean(), 1)} % of its mean"
        positive = above[(above["ssw_N"] > 0) & (above["F_m_N"] > 0)]
        power = fit_power_law(positive["F_m_N"].to_numpy(), positive["ssw_N"].to_numpy())
        if len(positive) >= 3 and math.isfinite(power.exponent):
            tested += 1
            ok = ok and abs(power.exponent - 1) <= TOLERANCES["ssw_exponent"]
            text += f", exponent {plus_minus(power.exponent, power.exponent_stderr, 3)}"
        else:
            text += f", {len(rows) - len(above)} of {len(rows)} points upper limits"
        parts.append(text)
    why = "" if ok else "the free exponent differs from 1"
    if not tested:
        why = "no chain has 3 SSW values above their errors (all upper limits)"
    if model == "elastic" and source == "simulation":
        # The Hertz chain launched from its ends is self-similar (F ~ V0^(6/5)).
        parts.append("self-similar chain: the scatter is the sampling")
    return _claim(
        f"SSW amplitude ∝ F_m ({named(summary, source, model)})",
        "proportional, no value",
        "; ".join(parts),
        (ok if tested else None),
        why,
    )


def _ratio_text(ratio: dict) -> str:
    return plus_minus(ratio["ratio"], ratio["ratio_err"], 2)


def _parity_claim(summary, fits) -> list[dict]:
    """Even > odd at the sensors (slope ratio N = 26 / 25) and far from the collision
    point (long chains, ``ssw_far_field``)."""
    parts, decisive, wrong = [], [], []
    for (source, model, n), even in sorted(fits.items(), key=str):
        odd = fits.get((source, model, n - 1)) if isinstance(n, int) and n % 2 == 0 else None
        if odd is None:
            continue
        ratio = ratio_with_error(
            even["slope"], even["slope_stderr"], odd["slope"], odd["slope_stderr"]
        )
        parts.append(f"at the sensors, {named(summary, source, model)}: {_ratio_text(ratio)}")
        decisive.append(ratio["ratio"] - 2 * ratio["ratio_err"] > 1)
        wrong.append(ratio["ratio"] < 1)
    for row in summary.get("ssw_far_field") or []:
        parts.append(
            f"far field ({row['model']}, N = {row['even_N']} / {row['odd_N']}): "
            f"{fixed(100 * row['even'], 2)} / {fixed(100 * row['odd'], 2)} % of F_m = "
            f"{_ratio_text(row)}"
        )
        decisive.append(row["ratio"] - 2 * row["ratio_err"] > 1)
        wrong.append(row["ratio"] < 1)
    if not parts:
        return [_claim("SSW larger in even chains", "larger, no ratio", NOT_COMPUTED, None,
                       "no SSW slope of an even and an odd chain, no long chains")]  # fmt: skip
    # A number exists, so never "not testable": within 2 errors of 1 is "not shown".
    ok = any(decisive) and not any(wrong)
    why = "" if ok else "some series give the odd chain the larger SSW"
    if not ok and not any(wrong):
        why = "not shown: even / odd above 1 but within 2 errors everywhere (template misfit)"
    elif ok and not all(decisive):
        why = (
            "decided far from the collision point; at the sensors within 2 errors (template misfit)"
        )
    return [
        _claim(
            "SSW larger in even chains",
            "larger, no ratio",
            "even / odd: " + "; ".join(parts),
            ok,
            why,
        )
    ]


def _experiment_claim(summary, fits) -> list[dict]:
    """Experiment's SSW slope over the simulation's, per chain and simulation model."""
    parts, excess = [], []
    for (source, _, n), fit in sorted(fits.items(), key=str):
        if source != "experiment":
            continue
        for (s_source, s_model, s_n), sim in sorted(fits.items(), key=str):
            if s_source != "simulation" or s_n != n:
                continue
            stat = ratio_with_error(fit["slope"], _stat(fit), sim["slope"], _stat(sim))
            total = ratio_with_error(
                fit["slope"], fit["slope_stderr"], sim["slope"], sim["slope_stderr"]
            )
            parts.append(
                f"N = {n}, / {s_model}: {plus_minus(stat['ratio'], stat['ratio_err'], 2)} stat "
                f"(± {fixed(total['ratio_err'], 2)} total)"
            )
            excess.append(total["ratio"] - 2 * total["ratio_err"] > 1)
    virtual = is_virtual(summary.get("experiment_label", ""))
    name = VIRTUAL_LABEL if virtual else "measured"
    if not parts:
        return [_claim("Simulated SSW much smaller than measured", "much smaller, no value",
                       NOT_COMPUTED, None, "no experiment SSW slope in this run")]  # fmt: skip
    ok = all(excess)
    why = ""
    if not ok:
        why = (
            "not reproduced by the model; see the mechanism study (the virtual apparatus "
            "has no mechanism for a larger SSW)"
            if virtual
            else "the measured SSW is not larger than the simulated one beyond 2 errors"
        )
    return [
        _claim(
            "Simulated SSW much smaller than measured",
            "much smaller, no value",
            f"{name} / simulation SSW slope: " + "; ".join(parts),
            ok,
            why,
        )
    ]


def _ssw_claims(summary, ssw: pd.DataFrame | None) -> list[dict]:
    """SSW ∝ F_m; larger in even chains; simulated SSW smaller than measured."""
    fits = _ssw_fit_rows(summary)
    rows = _ssw_rows(ssw)
    out = [
        _proportional_claim(summary, source, model, group, fits)
        for (source, model), group in rows.groupby(["source", "model"], sort=False)
    ]
    return out + _parity_claim(summary, fits) + _experiment_claim(summary, fits)


def energy_drift_within_paper(drift: float | None) -> bool | None:
    """Whether the conservative runs' largest relative energy drift is within the
    paper's order (:data:`PAPER_ENERGY_DRIFT`, Sec. II); None without any."""
    return None if drift is None else bool(drift <= PAPER_ENERGY_DRIFT)


def _drift_claim(summary) -> list[dict]:
    drift = summary.get("max_energy_drift")
    ok = energy_drift_within_paper(drift)
    return [
        _claim(
            "Energy conserved by the integrator (conservative chain)",
            f"~{power_of_ten(PAPER_ENERGY_DRIFT, 1)}",
            NOT_COMPUTED if drift is None else power_of_ten(drift),
            ok,
            "" if ok in (None, True) else "larger drift",
        )
    ]


def claims(summary: Mapping, delays=None, ssw=None) -> list[dict]:
    """The claim-by-claim table: claim | paper | ours | agrees | why not.

    Parameters
    ----------
    summary : mapping
        The run's ``summary.json``.
    delays, ssw : DataFrame, optional
        ``delays.csv`` (the sign of Δ) and ``ssw.csv`` (the SSW exponent against F_m).

    Returns
    -------
    list of dict
        Keys ``claim``, ``paper`` (the paper's number or statement), ``ours``,
        ``agrees`` ("yes", "no" or "not testable", from :data:`TOLERANCES`), ``why``.
    """
    return [
        *_early_claim(summary, delays),
        *_exponent_claims(summary),
        *_ballistic_claims(summary),
        *_c_claims(summary),
        *_dissipation_claim(summary),
        *_ssw_claims(summary, ssw),
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
