"""The run's headline numbers beside the paper's: ``summary.json`` and ``summary.md``.

Every number is computed from the run's tables and the closed forms of
:mod:`chain.physics.theory`, except the paper's own values in :data:`PAPER`, quoted as
printed. :func:`build_summary` gathers them into a JSON-ready dict,
:func:`summary_markdown` renders the side-by-side table, and :func:`write_summary`
writes both atomically with sorted keys and fixed float formatting.
"""

from __future__ import annotations

import json
import logging
import math
import os
from collections.abc import Iterable, Mapping

import numpy as np
import pandas as pd

from chain.analysis.rows import flag_counts, is_ok
from chain.analysis.selection import selection_counts
from chain.atomic import write_text_atomic
from chain.physics.theory import (
    HERTZ_TIME_CONSTANT,
    PAPER_TIME_CONSTANT,
    ballistic_constants,
)
from chain.report.paper import PAPER, PAPER_ENERGY_DRIFT

#: Significant digits of floats in summary.json.
JSON_DIGITS = 10

log = logging.getLogger(__name__)


def _number(value):
    """A JSON value: Python int/float/str/bool/None, floats to JSON_DIGITS digits."""
    if value is None:
        return None
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        value = float(value)
        if not math.isfinite(value):
            return None
        return float(f"{value:.{JSON_DIGITS}g}")
    if isinstance(value, str):
        return value
    if isinstance(value, Mapping):
        return {str(k): _number(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_number(v) for v in value]
    if pd.isna(value):
        return None
    return str(value)


def _records(table: pd.DataFrame | None) -> list[dict]:
    if table is None:
        return []
    records = []
    for row in table.to_dict("records"):
        if "N" in row and str(row["N"]) != "pooled":
            row["N"] = int(float(row["N"]))
        records.append(_number(row))
    return records


def build_summary(
    *,
    run_name: str,
    material: str,
    radius_m: float,
    delay_fits: pd.DataFrame,
    ssw_fits: pd.DataFrame,
    runs: pd.DataFrame | None = None,
    conservative_models: Iterable[str] = ("elastic",),
    main_estimator: str = "fit_full",
    experiment_label: str = "experiment",
    pulses: pd.DataFrame | None = None,
    delays: pd.DataFrame | None = None,
    ssw: pd.DataFrame | None = None,
    selection: pd.DataFrame | None = None,
    tolerance: float | None = None,
) -> dict:
    """The contents of ``summary.json``.

    Parameters
    ----------
    run_name : str
        Name of the run.
    material : str
        Bead material name.
    radius_m : float
        Bead radius, m.
    delay_fits : DataFrame
        ``delay_fits.csv``.
    ssw_fits : DataFrame
        ``ssw_fits.csv``.
    runs : DataFrame, optional
        The simulation runs tables (``model``, ``energy_drift`` per shot).
    conservative_models : iterable of str
        Models without dissipation, whose energy drift measures the integration error.
    main_estimator : str
        Estimator of the headline numbers.
    experiment_label : str
        Name of ``source == "experiment"`` rows in summary.md ("virtual experiment
        (model)" for the model of the apparatus).
    pulses, delays, ssw : DataFrame, optional
        ``pulses.csv``, ``delays.csv``, ``ssw.csv``: their flagged rows are counted.
    selection : DataFrame, optional
        ``experiment/selection.csv``: kept and rejected shots are counted.
    tolerance : float, optional
        The acceptance tolerance that made ``selection`` (fraction).

    Returns
    -------
    dict
        ``run_name``, ``material``, ``radius_m``, ``main_estimator``,
        ``conservative_models``, ``constants``,
        ``paper``, ``max_energy_drift`` (largest relative drift of the conservative
        runs, None without any), ``energy_drift_by_model``, ``delay_fits`` and
        ``ssw_fits`` (the rows of the tables), ``flagged`` (per table and source:
        ``rows``, ``flagged`` = ok False, ``nan`` = ok but a NaN value; ssw counts the
        ``residual`` rows, the ones fitted and drawn), ``selection`` (kept/rejected
        shots per series, N and kind) and ``experiment_tolerance``.
    """
    conservative = set(conservative_models)
    drift_by_model = {}
    max_drift = None
    if runs is not None and len(runs):
        drift_by_model = {
            str(model): float(group["energy_drift"].max())
            for model, group in runs.groupby("model", sort=True)
        }
        drifts = [v for k, v in drift_by_model.items() if k in conservative]
        max_drift = max(drifts) if drifts else None
    return _number(
        {
            "run_name": run_name,
            "material": material,
            "radius_m": radius_m,
            "main_estimator": main_estimator,
            "experiment_label": experiment_label,
            "conservative_models": sorted(conservative),
            "constants": ballistic_constants(material, radius_m),
            "paper": dict(PAPER),
            "max_energy_drift": max_drift,
            "energy_drift_by_model": drift_by_model,
            "delay_fits": _records(delay_fits),
            "ssw_fits": _records(ssw_fits),
            "flagged": {
                "pulses": flag_counts(pulses, ["F_m_N", "T_s"]),
                "delays": flag_counts(delays, ["F_m_N", "delay_us"]),
                "ssw": flag_counts(_residual_rows(ssw), ["F_m_N", "ssw_N"]),
            },
            "selection": selection_counts(selection),
            "experiment_tolerance": tolerance,
            "attenuation": attenuation_rows(pulses, main_estimator),
        }
    )


def attenuation_rows(pulses: pd.DataFrame | None, estimator: str = "fit_full") -> list[dict]:
    """How much a lone wave loses between the sensors: F_m(S2) / F_m(S1) of the
    simulated reference shots at the smallest and largest amplitude, per model and N.

    Dissipation that grows with amplitude explains why C and the exponent of a
    dissipative model differ from the conservative one: the waves cross with less than
    the F_m measured at S1, by an amplitude-dependent fraction.

    Parameters
    ----------
    pulses : DataFrame or None
        ``pulses.csv``.
    estimator : str
        Estimator whose F_m is used.
    """
    if pulses is None or not len(pulses):
        return []
    rows = pulses[
        (pulses["source"] == "simulation")
        & (pulses["kind"] == "reference")
        & (pulses["estimator"] == estimator)
        & is_ok(pulses)
    ]
    out = []
    for (model, n_beads), group in rows.groupby(["model", "N"], sort=True):
        first = group[group["sensor"] == "S1"].set_index("amplitude")["F_m_N"]
        second = group[group["sensor"] == "S2"].set_index("amplitude")["F_m_N"]
        ratio = (second / first).dropna()
        if len(ratio) < 2:
            continue
        low, high = first[ratio.index].idxmin(), first[ratio.index].idxmax()
        out.append(
            {
                "model": str(model),
                "N": int(n_beads),
                "F_S1_low_N": float(first[low]),
                "ratio_low": float(ratio[low]),
                "F_S1_high_N": float(first[high]),
                "ratio_high": float(ratio[high]),
            }
        )
    return out


def summary_json(summary: Mapping) -> str:
    """``summary`` as JSON text: sorted keys, two-space indent, no NaN, final newline."""
    return json.dumps(_number(dict(summary)), sort_keys=True, indent=2, allow_nan=False) + "\n"


def _percent(value: float, reference: float) -> str:
    return f"{100.0 * (value / reference - 1.0):+.1f} %"


def _pm(value, error, digits=2) -> str:
    """``value ± error`` with the error to two significant digits (at least ``digits``
    decimals), or ``n/a``."""
    if value is None:
        return "n/a"
    if error is None or not error > 0:
        return f"{value:.{digits}f}"
    decimals = min(8, max(digits, 1 - math.floor(math.log10(error))))
    return f"{value:.{decimals}f} ± {error:.{decimals}f}"


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


def summary_markdown(summary: Mapping) -> str:
    """The side-by-side table of ``summary.md``: quantity | paper | this run | note.

    Parameters
    ----------
    summary : mapping
        The dict of :func:`build_summary`.
    """
    paper = summary["paper"]
    constants = summary["constants"]
    main = summary["main_estimator"]
    label = summary.get("experiment_label", "experiment")
    c_exp, c_exp_err, c_bal = (
        paper["C_exp_us_N16"],
        paper["C_exp_err_us_N16"],
        paper["C_bal_us_N16"],
    )
    c_paper, c_exact = constants["C_bal_paper_us_N16"], constants["C_bal_exact_us_N16"]
    exact_ratio = 2.0 ** (-0.4) * HERTZ_TIME_CONSTANT / PAPER_TIME_CONSTANT
    steel = summary["material"] == "steel_100C6" and abs(summary["radius_m"] - 0.013) < 1e-12
    rows = [
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
            f"{c_exp:.1f} ± {c_exp_err:.1f}",
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
    fits = sorted(
        summary["delay_fits"],
        key=lambda r: (
            r["source"],
            r["model"],
            r["N"] == "pooled",
            str(r["N"]),
            r["estimator"] != main,
            r["estimator"],
        ),
    )
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
    rows += _dissipation_rows(summary, main)
    slopes = {
        (r["source"], r["model"], r["N"]): r
        for r in summary["ssw_fits"]
        if r.get("slope") is not None
    }
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
        rows.append(
            (
                f"SSW slope, {_who(row, label)}",
                paper_text,
                _pm(row.get("slope"), row.get("slope_stderr"), 4)
                if row.get("slope") is not None
                else "n/a",
                note,
            )
        )
    rows += _selection_rows(summary, label)
    rows += _flagged_rows(summary, label)
    drift = summary.get("max_energy_drift")
    rows.append(
        (
            "largest relative energy drift, conservative runs",
            f"~{PAPER_ENERGY_DRIFT:.0e} (Sec. II)",
            "n/a (no conservative model)" if drift is None else f"{drift:.2e}",
            ""
            if drift is None
            else ("within" if drift <= PAPER_ENERGY_DRIFT else "above")
            + " the paper's order of magnitude",
        )
    )
    lines = [
        f"# Summary of run `{summary['run_name']}`",
        "",
        f"Beads: {summary['material']}, R = {summary['radius_m'] * 1e3:g} mm; "
        f"κ = {constants['kappa_N_m1_5']:.4g} N/m^1.5, "
        f"m = {constants['bead_mass_kg'] * 1e3:.4g} g. Headline estimator: `{main}`. "
        "Paper values are quoted as printed in Santibanez et al. (Eq. 6, Fig. 4 caption, "
        "Sec. II); every other number is computed by this run.",
        "",
        "| quantity | paper | this run | note |",
        "|---|---|---|---|",
    ]
    lines += [f"| {q} | {p} | {r} | {n} |" for q, p, r, n in rows]
    lines += [
        "",
        "Notes",
        "",
        "* Δ = TOF(crossed) − TOF(reference) between the two sensors; |Δ| is fitted. In a "
        "simulation the LSTW and RSTW points are mirror images and count twice, so their "
        "standard errors are about √2 too small.",
        "* The simulation has no track friction; the paper attributes the small difference "
        "between its measured and simulated Δ to friction lengthening the pulses, and the "
        "large measured SSW to bead rotation and friction, neither of which is modelled.",
        "* The paper states that viscoelastic dissipation leaves Δ unchanged (Sec. V); the "
        "rows C(model) / C(conservative model) test that on this run.",
        *_attenuation_notes(summary),
        "",
    ]
    return "\n".join(lines)


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


def _dissipation_rows(summary, main) -> list[tuple[str, str, str, str]]:
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


def _residual_rows(ssw: pd.DataFrame | None) -> pd.DataFrame | None:
    """The SSW rows that are fitted and drawn (method ``residual``)."""
    if ssw is None or "method" not in ssw.columns:
        return ssw
    return ssw[ssw["method"] == "residual"]


def _selection_rows(summary, label) -> list[tuple[str, str, str, str]]:
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


def _flagged_rows(summary, label) -> list[tuple[str, str, str, str]]:
    """How many table rows were flagged (ok False) or NaN, and so left out."""
    flagged = summary.get("flagged") or {}
    parts = []
    for table, by_source in flagged.items():
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


def write_summary(
    summary: Mapping, json_path: str | os.PathLike, markdown_path: str | os.PathLike
) -> None:
    """Write ``summary.json`` and ``summary.md`` atomically (temporary name, then rename).

    Parameters
    ----------
    summary : mapping
        The dict of :func:`build_summary`.
    json_path, markdown_path : path
        Destinations.
    """
    write_text_atomic(summary_json(summary), json_path)
    write_text_atomic(summary_markdown(summary), markdown_path)
