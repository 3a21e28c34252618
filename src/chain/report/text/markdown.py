"""``summary.md``: the run's numbers beside the paper's, as a Markdown table.

:func:`summary_markdown` renders ``summary.json`` (the dict of
:func:`chain.report.numbers.summary.build_summary`) as rows ``quantity | paper | this
run | note``, one row builder per kind of number (constants, C per fit, exponents,
dissipation, selection, flagged rows, energy drift; the SSW rows in
:mod:`.markdown_ssw`, the studies in :mod:`.markdown_studies`), then the notes
(:mod:`.markdown_notes`). Only wording and layout live here: verdicts, ratios,
tolerances and series names are read from the summary, never decided; editing this
module rewrites ``summary.md`` and reruns nothing else.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path

from chain.atomic import write_text_atomic
from chain.labels import SKIPPED_REASON
from chain.report.naming import is_virtual, named
from chain.report.numbers.paper import PAPER_ENERGY_DRIFT
from chain.report.printed import number, percent, plus_minus, power_of_ten
from chain.report.text.markdown_notes import notes
from chain.report.text.markdown_ssw import Row, ssw_rows
from chain.report.text.markdown_studies import mechanism_markdown, spread_markdown_rows


def summary_markdown(summary: Mapping) -> str:
    """The side-by-side table of ``summary.md``: quantity | paper | this run | note, of
    ``summary`` (the dict of :func:`chain.report.numbers.summary.build_summary`)."""
    main = summary["main_estimator"]
    label = summary.get("experiment_label", "experiment")
    fits = _sorted_fits(summary["delay_fits"], main)
    rows = _constant_rows(summary, main, label)
    rows += _c_rows(summary, fits)
    rows += _exponent_rows(summary, fits, main)
    rows += _dissipation_rows(summary, main)
    rows += ssw_rows(summary)
    rows += spread_markdown_rows(summary)
    rows += _selection_rows(summary)
    rows += _skipped_rows(summary)
    rows += _flagged_rows(summary, label)
    rows.append(_energy_row(summary))
    lines = [
        f"# Summary of run `{summary['run_name']}`",
        "",
        _beads_line(summary),
        "",
        "| quantity | paper | this run | note |",
        "|---|---|---|---|",
    ]
    lines += [f"| {q} | {p} | {r} | {n} |" for q, p, r, n in rows]
    lines += mechanism_markdown(summary)
    lines += ["", "Notes", "", *notes(summary), ""]
    return "\n".join(lines)


def _beads_line(summary) -> str:
    constants = summary["constants"]
    return (
        f"Beads: {summary['material']}, R = {summary['radius_m'] * 1e3:g} mm; "
        f"κ = {number(constants['kappa_N_m1_5'], 4, 'unicode')} N/m^1.5, "
        f"m = {constants['bead_mass_kg'] * 1e3:.4g} g. Headline estimator: "
        f"`{summary['main_estimator']}`. "
        "Paper values are quoted as printed in Santibanez et al. (Eq. 6, Fig. 4 caption, "
        "Sec. II); every other number is computed by this run."
    )


def _paper_beads(summary) -> bool:
    """Whether the run's beads are the paper's (decided in the summary: ``paper_beads``)."""
    return bool(summary["paper_beads"]["same"])


def _sorted_fits(delay_fits, main) -> list:
    """Delay fits by source, model, chain (pooled last), the main estimator first."""
    return sorted(
        delay_fits,
        key=lambda r: (
            r["source"],
            r["model"],
            r["N"] == "pooled",
            str(r["N"]),
            r["estimator"] != main,
            r["estimator"],
        ),
    )


def _constant_rows(summary, main, label) -> list[Row]:
    """C_bal as printed and with the exact contact time, and the experiment's C."""
    paper, constants = summary["paper"], summary["constants"]
    c_bal = paper["C_bal_us_N16"]
    c_paper, c_exact = constants["C_bal_paper_us_N16"], constants["C_bal_exact_us_N16"]
    factors = summary["ballistic_factors"]
    steel = _paper_beads(summary)
    return [
        (
            "C_bal, Eq. 6 as printed (µs N^1/6)",
            f"{c_bal:.2f}",
            f"{c_paper:.2f}",
            (
                f"recomputed from rho, Y, nu, R: {100 * (c_paper / c_bal - 1):+.2f} % from the "
                "printed value"
                if steel
                else f"{summary['material']} beads, R = {summary['radius_m'] * 1e3:g} mm: "
                "not the paper's beads"
            ),
        ),
        (
            "C_bal, exact Hertz contact time (µs N^1/6)",
            "—",
            f"{c_exact:.2f}",
            "same ballistic argument with the exact two-bead contact time: Eq. 6 uses the "
            "mass m (a bead against an immovable body) where two free beads have reduced "
            f"mass m/2, and rounds {factors['hertz_time_constant']:.4f} to "
            f"{factors['paper_time_constant']:.2f}; ratio {factors['exact_over_paper']:.3f} "
            "(see chain.physics.theory.hertz_contact_time)",
        ),
        (
            "C_exp, experiment fit (µs N^1/6)",
            f"{paper['C_exp_us_N16']:.1f} ± {paper['C_exp_err_us_N16']:.1f}",
            _experiment_c(summary, main),
            "the paper's fit of its measurements, N = 25 and 26 pooled; "
            + (
                f"this run: its experiment series ({label}), chains pooled"
                + ("; a model of the apparatus, not data" if is_virtual(label) else "")
                if _has_experiment(summary)
                else "this run has no experiment"
            )
            + ("" if steel else "; not the paper's beads, so not comparable"),
        ),
    ]


def _c_rows(summary, fits) -> list[Row]:
    """C of every delay fit, against C_exp, C_bal and the exact-Hertz C_bal."""
    paper, constants = summary["paper"], summary["constants"]
    c_exp, c_exp_err, c_bal = (
        paper["C_exp_us_N16"],
        paper["C_exp_err_us_N16"],
        paper["C_bal_us_N16"],
    )
    c_exact = constants["C_bal_exact_us_N16"]
    steel = _paper_beads(summary)
    rows = []
    for row in fits:
        c, err = row.get("C_us_N16"), row.get("C_stderr_us_N16")
        if c is None:
            note = f"no fit ({row.get('n_points', 0)} points)"
        else:
            note = (
                f"{percent(c, c_bal)} vs C_bal (Eq. 6), {percent(c, c_exact)} vs exact-Hertz "
                f"C_bal; {row.get('n_points')} points"
            )
            if steel:
                note = f"{percent(c, c_exp)} vs paper's C_exp, " + note
        rows.append(
            (
                f"C, {named(summary, row['source'], row['model'], row['N'])}, "
                f"{row['estimator']} (µs N^1/6)",
                f"{c_exp:.1f} ± {c_exp_err:.1f} (experiment)"
                if steel
                else f"— (the paper's beads are {summary['paper_beads']['material']})",
                _pm(c, err),
                note,
            )
        )
    return rows


def _exponent_rows(summary, fits, main) -> list[Row]:
    """The free power law's exponent of each fit of the main estimator, against −1/6."""
    rows = []
    for row in fits:
        if row["estimator"] != main:
            continue
        p, err = row.get("exponent"), row.get("exponent_stderr")
        note = "free power law |Δ| = A F_m^p"
        if p is not None and err:
            note += f"; {(p + 1 / 6) / err:+.1f} standard errors from −1/6"
        rows.append(
            (
                f"exponent p, {named(summary, row['source'], row['model'], row['N'])}, {main}",
                "−1/6 (Eq. 6)",
                _pm(p, err, 4),
                note,
            )
        )
    return rows


def _energy_row(summary) -> Row:
    """The conservative runs' largest energy drift against the paper's order (the
    verdict of ``summary["verdicts"]["energy_drift_within_paper"]``)."""
    drift = summary.get("max_energy_drift")
    within = summary["verdicts"]["energy_drift_within_paper"]
    return (
        "largest relative energy drift, conservative runs",
        f"~{power_of_ten(PAPER_ENERGY_DRIFT, 1, 'unicode')} (Sec. II)",
        "n/a (no conservative model)" if drift is None else power_of_ten(drift, 3, "unicode"),
        ""
        if within is None
        else f"{'within' if within else 'above'} the paper's order of magnitude",
    )


def _pm(value, error, digits=2) -> str:
    """``value ± error`` by the one rule of :func:`chain.report.printed.plus_minus`
    (``digits`` decimals when there is no error), or ``n/a``."""
    return plus_minus(value, error, digits, style="unicode")


def _dissipation_rows(summary, main) -> list[Row]:
    """C of each dissipative model over C of each conservative one (pooled N), with the
    verdict of ``summary["verdicts"]["dissipation"]``."""
    pooled = {
        r["model"]: r
        for r in summary["delay_fits"]
        if r["source"] == "simulation" and r["N"] == "pooled" and r["estimator"] == main
    }
    verdicts = summary["verdicts"]
    tolerance = f"{100 * verdicts['tolerances']['dissipation_ratio']:g} %"
    rows = []
    for v in verdicts["dissipation"]:
        model, base = v["model"], v["base"]
        verdict = "agrees with" if v["agrees"] else "differs from"
        rows.append(
            (
                f"C({model}) / C({base}), simulation, all N pooled, {main}",
                "1 (dissipation does not change Δ, Sec. V)",
                f"{v['ratio']:.3f}",
                f"{verdict} the paper's statement ({tolerance} tolerance); exponents "
                f"{_exponent(pooled[model])} and {_exponent(pooled[base])}",
            )
        )
    return rows


def _exponent(row) -> str:
    exponent = row.get("exponent")
    return f"{math.nan if exponent is None else exponent:.4f}"


def _selection_rows(summary) -> list[Row]:
    """One row per series: kept and rejected shots of the acceptance protocol."""
    counts = summary.get("selection") or []
    tolerance = summary.get("experiment_tolerance")
    limit = "the tolerance" if tolerance is None else f"{100 * tolerance:g} %"
    rows = []
    for model in dict.fromkeys(c["model"] for c in counts):
        parts = []
        for n in sorted({c["N"] for c in counts if c["model"] == model}):
            kinds = {c["kind"]: c for c in counts if c["model"] == model and c["N"] == n}
            text = []
            for kind, word in (("collision", "collisions"), ("reference", "references")):
                if kind in kinds:
                    c = kinds[kind]
                    text.append(f"{c['kept']} of {c['kept'] + c['rejected']} {word} kept")
            parts.append(f"N = {n}: " + ", ".join(text))
        rows.append(
            (
                f"acceptance protocol, {named(summary, 'experiment', model)}",
                "collisions kept if the incident amplitudes differ by ≤ 5 % (Sec. IV); "
                "no counts printed",
                "; ".join(parts),
                f"|F_L − F_R| / mean ≤ {limit}; every shot and the reason in "
                "experiment/selection.csv; rejected collisions are left out of Δ and SSW",
            )
        )
    return rows


def _skipped_rows(summary) -> list[Row]:
    """One row listing the shots left out for a dead or saturated channel, if any."""
    skipped = summary.get("skipped_shots") or []
    if not skipped:
        return []
    shown = [
        f"{s['model']} N = {s['N']} shot {s['shot']}: "
        + s["reason"].removeprefix(f"{SKIPPED_REASON}: ").replace("|", "/")
        for s in skipped[:10]
    ]
    more = f"; and {len(skipped) - 10} more" if len(skipped) > 10 else ""
    return [
        (
            "shots skipped for a dead or saturated channel",
            "—",
            f"{len(skipped)}: " + "; ".join(shown) + more,
            "experiment.bad_channels: skip; counted among the rejected shots above, every "
            "one with its reason in experiment/selection.csv",
        )
    ]


def _flagged_rows(summary, label) -> list[Row]:
    """How many table rows were flagged (ok False) or NaN, and so left out."""
    flagged = summary.get("flagged") or {}
    parts = []
    # In pipeline order, whatever order the JSON kept its keys in.
    order = {"pulses": 0, "delays": 1, "ssw": 2}
    for table, by_source in sorted(flagged.items(), key=lambda item: order.get(item[0], 9)):
        counts = []
        for source, c in sorted(by_source.items(), key=lambda item: item[0] != "simulation"):
            who = label if source == "experiment" else source
            text = f"{c['flagged']} of {c['rows']} ({who})"
            if c.get("nan"):
                text += f" + {c['nan']} ok but NaN"
            counts.append(text)
        if counts:
            parts.append(f"{table}: " + ", ".join(counts))
    if not parts:
        return []
    return [
        (
            "flagged rows (ok = False), left out of fits and figures",
            "—",
            "; ".join(parts),
            "the reason of each is in the table's reason column; ssw counts the residual "
            "rows (the fitted ones)",
        )
    ]


def _has_experiment(summary) -> bool:
    return any(r["source"] == "experiment" for r in summary["delay_fits"])


def _experiment_c(summary, main) -> str:
    rows = [
        r
        for r in summary["delay_fits"]
        if r["source"] == "experiment" and r["N"] == "pooled" and r["estimator"] == main
    ]
    if not rows:
        return "—"
    return "; ".join(
        f"{named(summary, 'experiment', r['model'])}: "
        f"{_pm(r.get('C_us_N16'), r.get('C_stderr_us_N16'), 1)}"
        for r in rows
    )


def write_summary_markdown(json_path: str | os.PathLike, markdown_path: str | os.PathLike) -> None:
    """Write ``summary.md`` (:func:`summary_markdown`) from a written ``summary.json``,
    atomically. Its own step, so that rewording the Markdown reruns nothing else.

    Parameters
    ----------
    json_path : path
        ``summary.json`` (:func:`chain.report.numbers.summary.write_summary_json`).
    markdown_path : path
        Destination.
    """
    summary = json.loads(Path(json_path).read_text())
    write_text_atomic(summary_markdown(summary), markdown_path)
