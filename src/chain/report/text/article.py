"""The reproduction as an article: ``results/<run_name>/article.pdf``.

The article's text lives in a typst source (``workflow/report/article.typ``); every
number in it comes from here. :func:`article_numbers` turns the run's ``summary.json``
into one JSON-ready dict of strings, each number already rounded as the article prints
it, with the claim table as the summary decided it and the studies' findings (``None``
when the run did not compute them: the article then says so); the paper's own numbers
are always printed as the paper's. :func:`compile_article` compiles the source with the
``typst`` package from PyPI.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from chain.atomic import atomic_output
from chain.report.naming import is_virtual, named
from chain.report.numbers.claim_rows import NOT_COMPUTED, fit_row, loss_text, series_models
from chain.report.numbers.paper import PAPER_ENERGY_DRIFT
from chain.report.printed import (
    fixed,
    percent,
    plus_minus,
    plus_minus_stat_sys,
    scientific,
    table_of,
    without_e_notation,
)
from chain.report.text.article_figures import CAPTIONS, figure_text
from chain.report.text.article_ssw_tables import (
    far_field_table,
    parity_table,
    resolution_table,
    separation_table,
)
from chain.report.text.article_tables import ablation_tables, c_spread_tables
from chain.report.text.markdown_studies import not_run_text


def fit_rows(summary: Mapping) -> list[dict]:
    """Every row of ``delay_fits``, printed: C ± stderr (2 decimals), exponent ± stderr
    (4 decimals), points. The article's appendix table."""
    order = {"fit_full": 0, "peak": 1, "fit_rise": 2}
    rows = sorted(
        summary["delay_fits"],
        key=lambda r: (
            r["source"] != "simulation",
            r["model"],
            r["N"] == "pooled",
            str(r["N"]),
            order.get(r["estimator"], 9),
            r["estimator"],
        ),
    )
    return [
        {
            "series": named(summary, r["source"], r["model"]),
            "N": "pooled" if r["N"] == "pooled" else str(r["N"]),
            "estimator": r["estimator"],
            "C": plus_minus(r.get("C_us_N16"), r.get("C_stderr_us_N16"), 2),
            "exponent": plus_minus(r.get("exponent"), r.get("exponent_stderr"), 4),
            "points": str(r.get("n_points", "")),
        }
        for r in rows
    ]


def ssw_slope_rows(summary: Mapping) -> list[dict]:
    """Every row of ``ssw_fits``, printed: slope ± statistical ± systematic error (4
    decimals; ± total where a table has no split), points (resolved)."""
    return [
        {
            "series": named(summary, r["source"], r["model"]),
            "N": str(r["N"]),
            "slope": _slope_text(r),
            "points": str(r.get("n_points", ""))
            + ("" if r.get("n_resolved") is None else f" ({r['n_resolved']} resolved)"),
        }
        for r in sorted(summary["ssw_fits"], key=lambda r: (r["source"], r["model"], str(r["N"])))
    ]


def _slope_text(row: Mapping) -> str:
    """'0.034 ± < 0.001 (stat) ± 0.021 (sys)' (slope, N/N), or slope ± stderr."""
    if row.get("slope_sys") is None:
        return plus_minus(row.get("slope"), row.get("slope_stderr"), 4)
    return plus_minus_stat_sys(row.get("slope"), row.get("slope_stat"), row["slope_sys"])


def findings(summary: Mapping) -> dict:
    """The SSW, ablation and C-spread findings of the run, printed, or None each.

    Reads the summary keys ``ssw_resolved``, ``ssw_separation``, ``ssw_parity_ratio``,
    ``ssw_far_field``, ``ablation`` ({verdict, rows}), ``ssw_mechanisms`` ({verdict,
    rows, lammps_check}) and ``c_spread`` ({headline_choice, min_us_N16, max_us_N16,
    rows}); an absent or empty key gives None.
    """
    resolved = summary.get("ssw_resolved") or None

    def label(source: str, model: str) -> str:
        return named(summary, source, model)

    ablation = summary.get("ablation") or None
    study = summary.get("ssw_mechanisms") or None
    spread = summary.get("c_spread") or None
    return {
        "ssw_resolved": resolution_table(resolved, label),
        "ssw_resolved_count": None
        if resolved is None
        else {
            "resolved": str(sum(bool(r.get("resolved")) for r in resolved)),
            "total": str(len(resolved)),
        },
        "ssw_separation": separation_table(summary.get("ssw_separation"), label),
        "ssw_parity_ratio": parity_table(summary.get("ssw_parity_ratio"), label),
        "ssw_far_field": far_field_table(summary.get("ssw_far_field"), label),
        "ablation": None
        if ablation is None
        else {
            "verdict": str(ablation.get("verdict", "")),
            "tables": ablation_tables(ablation.get("rows")),
        },
        "mechanisms": None
        if study is None
        else {
            "verdict": without_e_notation(study.get("verdict", "")),
            "table": table_of(study.get("rows")),
            "check": table_of(_check_rows(study.get("lammps_check"))),
        },
        "c_spread": None
        if spread is None
        else {
            "headline_choice": str(spread.get("headline_choice", "")),
            "min": fixed(spread.get("min_us_N16"), 2),
            "max": fixed(spread.get("max_us_N16"), 2),
            "tables": c_spread_tables(spread.get("rows")),
        },
    }


def _check_rows(rows) -> list[dict] | None:
    """The cross-check's rows as the article prints them: chain, model, both C, their
    relative difference and the largest trace difference over F_m."""
    if not rows:
        return None
    return [
        {
            "N": r["N"],
            "model": r["model"],
            "C kernel": r["C_kernel"],
            "C LAMMPS": r["C_lammps"],
            "C rel. diff.": r["rel_diff_C"],
            "max |trace diff| / F_m": r["max_trace_diff_over_Fm"],
        }
        for r in rows
    ]


def _model_numbers(summary) -> list[dict]:
    """Per series (source, model): pooled C and exponent, per-N C, and how far the
    other estimators' C lie from the main one's."""
    out = []
    for source in ("simulation", "experiment"):
        for model in series_models(summary, source):
            main = fit_row(summary, source, model, "pooled")
            if main is None or main.get("C_us_N16") is None:
                continue
            others = [
                f"{r['estimator']} {percent(r['C_us_N16'], main['C_us_N16'])}"
                for r in summary["delay_fits"]
                if (r["source"], r["model"], r["N"]) == (source, model, "pooled")
                and r["estimator"] != main["estimator"]
                and r.get("C_us_N16") is not None
            ]
            per_n = [
                {"N": str(r["N"]), "C": plus_minus(r["C_us_N16"], r["C_stderr_us_N16"], 2)}
                for r in summary["delay_fits"]
                if (r["source"], r["model"], r["estimator"]) == (source, model, main["estimator"])
                and r["N"] != "pooled"
            ]
            out.append(
                {
                    "source": source,
                    "model": model,
                    "who": named(summary, source, model),
                    "C": plus_minus(main["C_us_N16"], main["C_stderr_us_N16"], 2),
                    "exponent": plus_minus(main.get("exponent"), main.get("exponent_stderr"), 4),
                    "per_N": per_n,
                    "estimators": ", ".join(others),
                    "loss": loss_text(summary, model) if source == "simulation" else None,
                }
            )
    return out


def _selection_text(summary) -> str | None:
    """'N = 25: 17 of 24 collisions and 16 of 16 references kept; N = 26: ...'."""
    counts = summary.get("selection") or []
    parts = []
    for n in dict.fromkeys(c["N"] for c in counts):
        kinds = [
            f"{c['kept']} of {c['kept'] + c['rejected']} {c['kind']}s"
            for c in counts
            if c["N"] == n
        ]
        parts.append(f"N = {n}: {' and '.join(kinds)} kept")
    return "; ".join(parts) or None


def _dissipation_numbers(summary) -> list[dict]:
    """C and exponent of each dissipative model against each conservative one (pooled),
    the ratio as ``summary["verdicts"]["dissipation"]`` decided it."""
    out = []
    for verdict in summary["verdicts"]["dissipation"]:
        model, base = verdict["model"], verdict["base"]
        row = fit_row(summary, "simulation", model, "pooled")
        reference = fit_row(summary, "simulation", base, "pooled")
        out.append(
            {
                "model": model,
                "base": base,
                "ratio": f"{verdict['ratio']:.3f}",
                "exponent": fixed(row.get("exponent"), 4),
                "base_exponent": fixed(reference.get("exponent"), 4),
                "loss": loss_text(summary, model),
                "larger": verdict["ratio"] > 1,
                "flatter": (row.get("exponent") or -math.inf)
                > (reference.get("exponent") or math.inf),
            }
        )
    return out


def _between_ballistic(summary) -> bool:
    """Whether every simulated C (main estimator, per chain) lies between the ballistic
    C with the exact contact time and that of Eq. 6."""
    low = summary["constants"]["C_bal_exact_us_N16"]
    high = summary["constants"]["C_bal_paper_us_N16"]
    low, high = min(low, high), max(low, high)
    values = [
        r["C_us_N16"]
        for r in summary["delay_fits"]
        if r["source"] == "simulation"
        and r["N"] != "pooled"
        and r["estimator"] == summary["main_estimator"]
        and r.get("C_us_N16") is not None
    ]
    return bool(values) and all(low <= c <= high for c in values)


def _constants_text(summary) -> dict:
    constants, paper = summary["constants"], summary["paper"]
    drift = scientific(summary.get("max_energy_drift"))
    c_paper, c_exact = constants["C_bal_paper_us_N16"], constants["C_bal_exact_us_N16"]
    kappa = scientific(constants["kappa_N_m1_5"], 4)
    factors, tolerances = summary["ballistic_factors"], summary["verdicts"]["tolerances"]
    return {
        "run_name": summary["run_name"],
        "material": summary["material"],
        "radius_mm": f"{summary['radius_m'] * 1e3:g}",
        "kappa": kappa,
        "mass_g": f"{constants['bead_mass_kg'] * 1e3:.1f}",
        "estimator": summary["main_estimator"],
        "experiment_label": summary.get("experiment_label", "experiment"),
        "virtual": is_virtual(summary.get("experiment_label", "")),
        "has_experiment": bool(series_models(summary, "experiment")),
        "C_bal_printed": f"{paper['C_bal_us_N16']:.2f}",
        "C_bal_recomputed": f"{constants['C_bal_paper_us_N16']:.2f}",
        "C_bal_exact": f"{constants['C_bal_exact_us_N16']:.2f}",
        "exact_over_printed": f"{constants['C_bal_exact_us_N16'] / paper['C_bal_us_N16']:.3f}",
        "ballistic_gap": f"{abs(100 * (c_paper / c_exact - 1)):.0f} %",
        "simulation_between_ballistic": _between_ballistic(summary),
        "paper_drift": scientific(PAPER_ENERGY_DRIFT, 1),
        "mass_factor": f"{factors['reduced_mass_time_factor']:.3f}",
        "time_constant": f"{factors['hertz_time_constant']:.3f}",
        "paper_time_constant": f"{factors['paper_time_constant']:.2f}",
        "C_exp": f"{paper['C_exp_us_N16']:.1f} ± {paper['C_exp_err_us_N16']:.1f}",
        "drift": drift,
        "selection": _selection_text(summary),
        "tolerances": {
            "C": f"{100 * tolerances['C']:g} %",
            "C_bal_recomputed": f"{100 * tolerances['C_bal_recomputed']:g} %",
            "delay_exponent": f"{tolerances['delay_exponent']:g}",
            "dissipation_ratio": f"{100 * tolerances['dissipation_ratio']:g} %",
            "ssw_exponent": f"{tolerances['ssw_exponent']:g}",
        },
    }


def setup_text(setup: Mapping | None) -> dict:
    """The run's configuration as printed: chains and sensors, models and η, launch
    speeds, and the virtual experiment's apparatus (all optional keys)."""
    setup = setup or {}
    virtual = setup.get("virtual") or {}
    speeds = virtual.get("impact_speeds_m_s") or []
    launch = setup.get("launch") or {}
    return {
        "chains": [
            {"N": str(c["N"]), "S1": str(c["sensors"][0]), "S2": str(c["sensors"][1])}
            for c in setup.get("chains", [])
        ],
        "models": [
            {"name": m["name"], "eta_us": f"{m['eta_s'] * 1e6:g}"} for m in setup.get("models", [])
        ],
        "launch": None
        if not launch
        else {
            "count": str(launch["count"]),
            "min": f"{launch['v0_min_m_s']:g}",
            "max": f"{launch['v0_max_m_s']:g}",
        },
        "source": setup.get("source"),
        "virtual": None
        if not virtual
        else {
            "striker_mm": f"{setup.get('striker_radius_m', math.nan) * 1e3:g}",
            "speeds": f"{min(speeds):g} to {max(speeds):g}" if speeds else "n/a",
            "amplitudes": str(len(speeds)),
            "collisions": str(virtual.get("collision_shots", "")),
            "references": str(virtual.get("reference_shots", "")),
            "noise_N": f"{virtual.get('noise_N', math.nan):g}",
            "adc_bits": str(virtual.get("adc_bits", "")),
            "mismatch_percent": f"{100 * virtual.get('speed_mismatch', math.nan):g}",
            "jitter_us": f"{virtual.get('timing_jitter_s', math.nan) * 1e6:g}",
            "sampling_us": f"{virtual.get('sampling_interval_s', math.nan) * 1e6:g}",
            "eta_us": f"{virtual.get('eta_s', math.nan) * 1e6:g}",
        },
        "tolerance_percent": f"{100 * setup['tolerance']:g}" if setup.get("tolerance") else None,
    }


def article_numbers(
    summary: Mapping, setup: Mapping | None = None, provenance: Mapping | None = None
) -> dict:
    """Everything the article prints, as strings: the JSON that article.typ reads.

    Parameters
    ----------
    summary : mapping
        The run's ``summary.json``, with its decisions (``series_names``,
        ``ballistic_factors``, ``verdicts`` with the claim table: :func:`chain.report.
        numbers.claims.with_claims`).
    setup : mapping, optional
        Plain configuration values: ``chains`` (N, sensors), ``models`` (name, eta_s in
        s), ``launch`` (count, v0_min_m_s, v0_max_m_s in m/s), ``source`` (experiment
        source), ``virtual`` (the virtual experiment's keys, SI), ``striker_radius_m``
        (m) and ``tolerance`` (acceptance, fraction).
    provenance : mapping, optional
        :func:`chain.pipeline.provenance.record.run_provenance` of the run (commit, date,
        dirty, config_hash, versions); None prints "not recorded".

    Returns
    -------
    dict
        ``text`` (constants and labels), ``setup``, ``series`` (per source and model:
        pooled C, exponent, per-N C, estimator spread, attenuation), ``claims``,
        ``fits`` and ``ssw_slopes`` (every row, printed), ``findings`` (SSW, ablation,
        C spread; None where not computed), ``figure_text`` (section, caption and
        paragraph per known figure, :mod:`chain.report.text.article_figures`),
        ``provenance``, ``not_computed`` (the phrase for those) and ``absent`` (per
        study, "ablation", "c_sensitivity", "mechanisms": what the article says when its
        finding is None: not run in this run, or not computed).
    """
    if "claims" not in (summary.get("verdicts") or {}):
        raise ValueError(
            "summary.json has no verdicts['claims']: it was written before the claims were "
            "decided in the summary step; rerun that step (snakemake reruns it on the new code)"
        )
    return {
        "text": _constants_text(summary),
        "setup": setup_text(setup),
        "series": _model_numbers(summary),
        "dissipation": _dissipation_numbers(summary),
        "claims": summary["verdicts"]["claims"],
        "fits": fit_rows(summary),
        "ssw_slopes": ssw_slope_rows(summary),
        "findings": findings(summary),
        "figure_text": {name: figure_text(name, summary) for name in CAPTIONS},
        "provenance": provenance_text(provenance),
        "not_computed": NOT_COMPUTED,
        "absent": {
            study: not_run_text(summary, study) or NOT_COMPUTED
            for study in ("ablation", "c_sensitivity", "mechanisms")
        },
    }


def provenance_text(provenance: Mapping | None) -> dict:
    """The provenance as printed: ``source`` ('commit 0123456789ab, committed 2026-01-02',
    with 'with uncommitted changes' when the tree was dirty, or why there is no commit),
    ``config_hash`` and ``versions`` ('numpy 2.4.6, ...')."""
    if not provenance:
        return {"source": "an unrecorded checkout", "config_hash": "not recorded",
                "versions": "not recorded"}  # fmt: skip
    if provenance.get("date") is None:
        source = f"a copy of the workflow that is {provenance.get('commit')} (no commit date)"
    else:
        dirty = " with uncommitted changes" if provenance.get("dirty") else ""
        source = f"commit {provenance['commit']}{dirty}, committed {provenance['date']}"
    versions = provenance.get("versions") or {}
    return {
        "source": source,
        "config_hash": str(provenance.get("config_hash")),
        "versions": ", ".join(f"{k} {v}" for k, v in versions.items()) or "not recorded",
    }


def figure_entries(
    paths: Iterable[str | os.PathLike], root: Path, texts: Mapping | None = None
) -> list[dict]:
    """The run's figures for the article: ``name`` (file stem), ``path`` (from the typst
    root, with a leading ``/``), ``section``, ``caption`` and ``paragraph`` (from
    ``texts``, the ``figure_text`` of :func:`article_numbers`; a figure not in it gets
    the generic text of :func:`chain.report.text.article_figures.figure_text`)."""
    texts = texts or {}
    out = []
    for path in paths:
        path = Path(os.path.abspath(path))
        text = texts.get(path.stem) or figure_text(path.stem, {})
        out.append({"name": path.stem, "path": "/" + path.relative_to(root).as_posix(), **text})
    return out


def compile_article(
    source: str | os.PathLike,
    numbers: Mapping,
    figures: Iterable[str | os.PathLike],
    output: str | os.PathLike,
) -> None:
    """Compile the typst ``source`` into the PDF ``output`` (atomically).

    The numbers reach the source as ``sys.inputs.numbers`` (JSON, with the figure list
    added under ``figures``); the figures are embedded as they are (PDF: vector). Only
    the fonts bundled with typst are used, and the document date is left unset by the
    source, so the same inputs give the same bytes on any machine.

    Parameters
    ----------
    source : path
        The typst source (``workflow/report/article.typ``).
    numbers : mapping
        :func:`article_numbers`.
    figures : iterable of path
        The figure files (PDF), in the order the article lists unplaced ones.
    output : path
        Destination PDF.
    """
    import typst  # here: a compiler the rest of the library does not need

    source = Path(os.path.abspath(source))
    figures = [Path(os.path.abspath(path)) for path in figures]
    root = Path(os.path.commonpath([source.parent, *figures]))
    document = dict(numbers, figures=figure_entries(figures, root, numbers.get("figure_text")))
    pdf = typst.compile(
        str(source),
        root=str(root),
        sys_inputs={"numbers": json.dumps(document, sort_keys=True)},
        ignore_system_fonts=True,
    )
    with atomic_output(output) as temporary:
        Path(temporary).write_bytes(pdf)
