"""What every claim of the claim table is made of: the tolerances a verdict is decided
against, the row of a claim and its verdict, and the delay-fit rows a claim reads
(:mod:`chain.report.numbers.claims`, :mod:`chain.report.numbers.ssw_claims`)."""

from __future__ import annotations

from chain.report.printed import number

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


def verdict(ok: bool | None) -> str:
    """'yes', 'no' or 'not testable' (``ok`` None: nothing of this run to compare)."""
    return "not testable" if ok is None else ("yes" if ok else "no")


def claim_row(claim, paper, ours, ok, why="") -> dict:
    """A row of the claim table: the claim, the paper's number or statement, ours, the
    verdict of ``ok`` (:func:`verdict`) and why it does not agree."""
    return {"claim": claim, "paper": paper, "ours": ours, "agrees": verdict(ok), "why": why}


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
