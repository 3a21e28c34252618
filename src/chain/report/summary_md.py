"""``summary.md``: the run's numbers beside the paper's, as a Markdown table.

:func:`summary_markdown` renders the dict of :func:`chain.report.summary.build_summary`
as rows ``quantity | paper | this run | note``, one row builder per kind of number
(constants, C per fit, exponents, dissipation, SSW slopes, selection, flagged rows,
energy drift), then the notes. Only wording and layout live here: editing this module
rewrites ``summary.md`` and reruns nothing else.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping
from pathlib import Path

from chain.analysis.selection import SKIPPED_REASON
from chain.atomic import write_text_atomic
from chain.physics.theory import HERTZ_TIME_CONSTANT, PAPER_TIME_CONSTANT
from chain.report.mechanisms import mechanism_markdown
from chain.report.paper import PAPER_ENERGY_DRIFT
from chain.report.printed import plus_minus
from chain.report.spread import spread_markdown_rows

#: A row of the table: quantity, paper, this run, note.
Row = tuple[str, str, str, str]

#: The notes under the table (the attenuation note follows when the run has one).
NOTES = [
    "* Δ = TOF(crossed) − TOF(reference) between the two sensors; |Δ| is fitted. In a "
    "simulation the LSTW and RSTW points are mirror images and count twice, so their "
    "standard errors are about √2 too small.",
    "* The simulation (Eq. 1) has no track friction; the paper attributes the small "
    "difference between its measured and simulated Δ to friction lengthening the pulses, "
    "and the large measured SSW to bead rotation and friction. The mechanism study (3D "
    "beads with rotation and friction on LAMMPS, and the other candidates in the virtual "
    "apparatus) tests the second; its verdict is above when this run has it.",
    "* The paper states that viscoelastic dissipation leaves Δ unchanged (Sec. V); the "
    "rows C(model) / C(conservative model) test that on this run.",
    "* SSW at a sensor: the largest residual against the self-similar template behind the "
    "crossed pulse (behind its trailing minimum, else from one τ behind its peak), with a "
    "systematic error (the template misfit on the rising edge) and a statistical one (3 σ "
    "of the smoothed noise); a value not above its error is an upper limit. 'Resolved' is "
    "stricter: a distinct bump above 2 × (misfit + 3 σ). The slopes are weighted "
    "proportional fits of every measurable point: ± statistical (scatter) ± systematic "
    "(values shifted by their systematic error).",
    "* Along the simulated chain (tables/ssw_track.csv, figures/ssw_spacetime, Fig. 5b) "
    "the SSW is 'separated' where maxima at 3 or more neighbouring contacts link at Eq. "
    "5's transit time for their own size (within a factor 2): one rule for every model "
    "and N. Its far-field size comes from the long chains (config long_chains), at the "
    "farthest contact before the main pulse reaches the free end. Contact k joins beads "
    "k and k+1.",
    "* What the SSW rows show, and why (paper run; tests/test_ssw_track.py, "
    "docs/analysis.md): at the sensors the SSW is a shoulder, so its value is mostly the "
    "template misfit and the even / odd ratio there is within 2 errors of 1; it is decided "
    "far from the collision point. The elastic SSW's speed over Eq. 5 in the long chains, "
    "fitted from where it detaches, is 1.020 (even) and 1.031 (odd); fitted only where it "
    "has settled (20 beads on) both give 1.013, the main pulse's own ratio (Eq. 5 is a "
    "long-wavelength approximation): the excess is the SSW still growing over the first "
    "contacts (odd: 0.69 to 0.85 % of F_m). With Kuwabara-Kono dissipation no SSW "
    "separates in the paper's chains, but one does in the long chains, decaying along "
    "them and larger at larger F_m; the dissipative tail keeps the contact between it and "
    "the crossed pulse loaded, so it rarely detaches before the free end and its speed is "
    "mostly not measured.",
]


def summary_markdown(summary: Mapping) -> str:
    """The side-by-side table of ``summary.md``: quantity | paper | this run | note.

    Parameters
    ----------
    summary : mapping
        The dict of :func:`chain.report.summary.build_summary`.
    """
    main = summary["main_estimator"]
    label = summary.get("experiment_label", "experiment")
    fits = _sorted_fits(summary["delay_fits"], main)
    rows = _constant_rows(summary, main, label)
    rows += _c_rows(summary, fits, label)
    rows += _exponent_rows(fits, main, label)
    rows += _dissipation_rows(summary, main)
    rows += _ssw_rows(summary, label)
    rows += _ssw_resolved_rows(summary, label)
    rows += _ssw_separation_rows(summary)
    rows += _ssw_parity_rows(summary, label)
    rows += spread_markdown_rows(summary)
    rows += _selection_rows(summary, label)
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
    lines += ["", "Notes", "", *NOTES, *_attenuation_notes(summary), ""]
    return "\n".join(lines)


def _beads_line(summary) -> str:
    constants = summary["constants"]
    return (
        f"Beads: {summary['material']}, R = {summary['radius_m'] * 1e3:g} mm; "
        f"κ = {constants['kappa_N_m1_5']:.4g} N/m^1.5, "
        f"m = {constants['bead_mass_kg'] * 1e3:.4g} g. Headline estimator: "
        f"`{summary['main_estimator']}`. "
        "Paper values are quoted as printed in Santibanez et al. (Eq. 6, Fig. 4 caption, "
        "Sec. II); every other number is computed by this run."
    )


def _paper_beads(summary) -> bool:
    """Whether the run's beads are the paper's (steel 100C6, R = 13 mm)."""
    return summary["material"] == "steel_100C6" and abs(summary["radius_m"] - 0.013) < 1e-12


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
    exact_ratio = 2.0 ** (-0.4) * HERTZ_TIME_CONSTANT / PAPER_TIME_CONSTANT
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
            f"mass m/2, and rounds 2.9432 to 2.94; ratio {exact_ratio:.3f} "
            "(see chain.physics.theory.hertz_contact_time)",
        ),
        (
            "C_exp, experiment fit (µs N^1/6)",
            f"{paper['C_exp_us_N16']:.1f} ± {paper['C_exp_err_us_N16']:.1f}",
            _experiment_c(summary, main, label),
            "the paper's fit of its measurements, N = 25 and 26 pooled; "
            + (
                f"this run: its experiment series ({label}), chains pooled"
                + ("; a model of the apparatus, not data" if "virtual" in label else "")
                if _has_experiment(summary)
                else "this run has no experiment"
            )
            + ("" if steel else "; not the paper's beads, so not comparable"),
        ),
    ]


def _c_rows(summary, fits, label) -> list[Row]:
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
                f"{_percent(c, c_bal)} vs C_bal (Eq. 6), {_percent(c, c_exact)} vs exact-Hertz "
                f"C_bal; {row.get('n_points')} points"
            )
            if steel:
                note = f"{_percent(c, c_exp)} vs paper's C_exp, " + note
        rows.append(
            (
                f"C, {_who(row, label)}, {row['estimator']} (µs N^1/6)",
                f"{c_exp:.1f} ± {c_exp_err:.1f} (experiment)"
                if steel
                else "— (the paper's beads are steel_100C6)",
                _pm(c, err),
                note,
            )
        )
    return rows


def _exponent_rows(fits, main, label) -> list[Row]:
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
            (f"exponent p, {_who(row, label)}, {main}", "−1/6 (Eq. 6)", _pm(p, err, 4), note)
        )
    return rows


def _ssw_rows(summary, label) -> list[Row]:
    """The SSW slope of every fit; an even chain's against the odd chain below it."""
    slopes = {
        (r["source"], r["model"], r["N"]): r
        for r in summary["ssw_fits"]
        if r.get("slope") is not None
    }
    rows = []
    for row in sorted(summary["ssw_fits"], key=lambda r: (r["source"], r["model"], str(r["N"]))):
        note = "SSW amplitude = slope × F_m"
        if isinstance(row["N"], int) and row["N"] % 2 == 0:
            odd = slopes.get((row["source"], row["model"], row["N"] - 1))
            if odd and row.get("slope") is not None and odd["slope"]:
                ratio = row["slope"] / odd["slope"]
                note += f"; {ratio:.2f} × the N = {row['N'] - 1} slope (even / odd)"
        paper_text = "∝ F_m, larger for even N (no value printed)"
        if row["source"] == "simulation":
            paper_text += "; simulated SSW much smaller than measured"
        value = _pm(row.get("slope"), row.get("slope_stderr"), 4)
        if row.get("slope_stat") is not None and row.get("slope") is not None:
            value = (
                f"{_pm(row['slope'], row['slope_stat'], 4)} stat ± "
                f"{row.get('slope_sys', float('nan')):.4f} sys"
            )
            note += (
                f"; {row.get('n_points', 0)} points, {row.get('n_resolved', 0)} resolved "
                "(the rest measured or upper limits)"
            )
        if row.get("slope") is None:
            value = f"n/a ({row.get('n_points', 0)} points)"
            note = "no measurable SSW at the sensors: nothing to fit"
        rows.append((f"SSW slope, {_who(row, label)}", paper_text, value, note))
    return rows


def _ssw_resolved_rows(summary, label) -> list[Row]:
    """Whether the SSW is resolved at each sensor: yes/no with the count of shots."""
    rows = []
    for row in summary.get("ssw_resolved", []):
        counts = f"{row['n_resolved']} of {row['n_total']} shots"
        rows.append(
            (
                f"SSW resolved at {row['sensor']}, {_who(row, label)}",
                _paper_ssw_shown(row),
                f"{'yes' if row['resolved'] else 'no'} ({counts})",
                "a distinct bump behind the crossed pulse's trailing minimum, above "
                "2 × (template misfit + 3 σ noise); yes if in at least half the shots",
            )
        )
    return rows


def _paper_ssw_shown(row: Mapping) -> str:
    """What the paper shows of the SSW at the sensors of this chain (Fig. 2 and 3:
    panels C and D are the 26-bead chain)."""
    if row["N"] == 26:
        return "yes (Fig. 2 and 3, C and D)"
    if row["N"] == 25 and row["source"] == "experiment":
        return "yes (Sec. IV, odd and even N; not shown)"
    return "—"


def _ssw_separation_rows(summary) -> list[Row]:
    """Where the tracked SSW separates from the crossed pulse, and its speed / Eq. 5
    (LSTW; RSTW is its mirror image in the simulation)."""
    rows = []
    for row in summary.get("ssw_separation", []):
        if row["wave"] != "LSTW":
            continue
        who = f"simulation, {row['model']}, N = {row['N']}"
        shots = f"{row.get('n_shots_separated', 0)} of {row.get('n_shots', 0)} shots separate"
        contact = row["first_separated_contact"]
        where = "never within the chain"
        if contact is not None:
            where = f"contact {contact} ({row['distance_beads']:g} beads from the collision point)"
        rows.append((f"SSW first separated contact (LSTW), {who}", "—", where, shots))
        ratio = row.get("speed_ratio")
        rows.append(
            (
                f"SSW speed / Eq. 5 for its amplitude, {who}",
                "—",
                "n/a" if ratio is None else f"{ratio:.3f}",
                "fitted where detached from the crossed pulse, before the free end"
                if ratio is not None
                else "never separated"
                if contact is None
                else "not detached over 3 contacts before the free end unloads the chain",
            )
        )
    return rows


def _ssw_parity_rows(summary, label) -> list[Row]:
    """The SSW slope of N = 26 over N = 25 (the paper's even/odd claim)."""
    rows = []
    for row in summary.get("ssw_parity_ratio", []):
        who = _who({**row, "N": "26 : 25"}, label).replace("N = 26 : 25", "N = 26 : N = 25")
        ratio = row.get("ratio")
        rows.append(
            (
                f"SSW slope ratio, {who}",
                "> 1 (larger for even N, Sec. V)",
                "n/a" if ratio is None else _pm(ratio, row.get("ratio_err"), 2),
                "no SSW slope of one chain or both"
                if ratio is None
                else "at the sensors; the error is mostly the template misfit (systematic)",
            )
        )
    for row in summary.get("ssw_far_field", []):
        rows.append(
            (
                f"SSW far field, even : odd, simulation, {row['model']}, "
                f"N = {row['even_N']} : {row['odd_N']}",
                "> 1 (larger for even N, Sec. V)",
                _pm(row["ratio"], row["ratio_err"], 3),
                f"SSW / F_m = {_pm(100 * row['even'], 100 * row['even_err'], 3)} % : "
                f"{_pm(100 * row['odd'], 100 * row['odd_err'], 3)} % (long chains, at the "
                "farthest contact before the free end; error: shot spread and change over "
                "the last 3 contacts)",
            )
        )
    return rows


def _energy_row(summary) -> Row:
    """The conservative runs' largest energy drift against the paper's order."""
    drift = summary.get("max_energy_drift")
    return (
        "largest relative energy drift, conservative runs",
        f"~{PAPER_ENERGY_DRIFT:.0e} (Sec. II)",
        "n/a (no conservative model)" if drift is None else f"{drift:.2e}",
        ""
        if drift is None
        else ("within" if drift <= PAPER_ENERGY_DRIFT else "above")
        + " the paper's order of magnitude",
    )


def _percent(value: float, reference: float) -> str:
    return f"{100.0 * (value / reference - 1.0):+.1f} %"


def _pm(value, error, digits=2) -> str:
    """``value ± error`` by the one rule of :func:`chain.report.printed.plus_minus`
    (``digits`` decimals when there is no error), or ``n/a``."""
    return plus_minus(value, error, digits, style="unicode")


def _who(row: Mapping, experiment_label: str = "experiment") -> str:
    n = row["N"]
    chains = "all N pooled" if n == "pooled" else f"N = {n}"
    if row["source"] == "experiment":
        # The label may name the series already ("virtual experiment (model)" for
        # "virtual", "measured (lab2011)" for "lab2011").
        if str(row["model"]) in experiment_label:
            return f"{experiment_label}, {chains}"
        return f"{experiment_label}, {row['model']}, {chains}"
    return f"{row['source']}, {row['model']}, {chains}"


def _attenuation_notes(summary) -> list[str]:
    rows = summary.get("attenuation") or []
    if not rows:
        return []
    parts = [
        f"{r['model']}, N = {r['N']}: {1 - r['ratio_low']:.1%} at {r['F_S1_low_N']:.3g} N, "
        f"{1 - r['ratio_high']:.1%} at {r['F_S1_high_N']:.3g} N"
        for r in rows
    ]
    return [
        "* Amplitude lost by a lone (reference) wave between S1 and S2: "
        + "; ".join(parts)
        + ". With Kuwabara-Kono dissipation the loss per contact grows like η/τ ∝ F_m^(1/6), "
        "so the waves cross with less than the F_m measured at S1, by a fraction that grows "
        "with F_m: C rises and the fitted exponent is flatter than −1/6. The ballistic "
        "argument of Eq. 6 assumes the amplitude at the crossing is the measured one."
    ]


def _dissipation_rows(summary, main) -> list[Row]:
    """C of each dissipative model over C of each conservative one (pooled N)."""
    pooled = {
        r["model"]: r
        for r in summary["delay_fits"]
        if r["source"] == "simulation"
        and r["N"] == "pooled"
        and r["estimator"] == main
        and r.get("C_us_N16") is not None
    }
    conservative = summary.get("conservative_models", [])
    rows = []
    for base in conservative:
        for model, row in pooled.items():
            if model in conservative or base not in pooled:
                continue
            ratio = row["C_us_N16"] / pooled[base]["C_us_N16"]
            verdict = "agrees with" if abs(ratio - 1) < 0.02 else "differs from"
            rows.append(
                (
                    f"C({model}) / C({base}), simulation, all N pooled, {main}",
                    "1 (dissipation does not change Δ, Sec. V)",
                    f"{ratio:.3f}",
                    f"{verdict} the paper's statement (2 % tolerance); exponents "
                    f"{row.get('exponent', math.nan):.4f} and "
                    f"{pooled[base].get('exponent', math.nan):.4f}",
                )
            )
    return rows


def _selection_rows(summary, label) -> list[Row]:
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
                f"acceptance protocol, {label if model in label else f'{label}, {model}'}",
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


def _experiment_c(summary, main, label="experiment") -> str:
    rows = [
        r
        for r in summary["delay_fits"]
        if r["source"] == "experiment" and r["N"] == "pooled" and r["estimator"] == main
    ]
    if not rows:
        return "—"
    return "; ".join(
        f"{label if r['model'] in label else r['model']}: "
        f"{_pm(r.get('C_us_N16'), r.get('C_stderr_us_N16'), 1)}"
        for r in rows
    )


def write_summary_markdown(json_path: str | os.PathLike, markdown_path: str | os.PathLike) -> None:
    """Write ``summary.md`` (:func:`summary_markdown`) from a written ``summary.json``,
    atomically. Its own step, so that rewording the Markdown reruns nothing else.

    Parameters
    ----------
    json_path : path
        ``summary.json`` (:func:`chain.report.summary.write_summary_json`).
    markdown_path : path
        Destination.
    """
    summary = json.loads(Path(json_path).read_text())
    write_text_atomic(summary_markdown(summary), markdown_path)
