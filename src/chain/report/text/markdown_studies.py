"""``summary.md``'s rows and lines for the studies: the ablation of the virtual
experiment, the spread of C over our choices (summary keys ``ablation`` and
``c_spread``) and the mechanism study (``ssw_mechanisms``), or that the config switched
a study off (``studies_not_run``). Wording only: the verdicts are the summary's
(:mod:`chain.report.numbers.spread`, :mod:`chain.report.numbers.mechanisms`)."""

from __future__ import annotations

from collections.abc import Mapping

from chain.labels import VIRTUAL_LABEL
from chain.report.printed import power_of_ten, without_e_notation


def not_run_text(summary: Mapping, study: str) -> str | None:
    """'not run in this run (config studies.<study>: false)' when the config switched
    the study off (summary ``studies_not_run``), else None."""
    if study not in (summary.get("studies_not_run") or ()):
        return None
    return f"not run in this run (config studies.{study}: false)"


def spread_markdown_rows(summary: Mapping) -> list[tuple[str, str, str, str]]:
    """``summary.md`` rows (quantity | paper | this run | note) for both keys, if
    present, or saying that the study was not run."""
    rows = []
    ablation = summary.get("ablation")
    ablation_off = not_run_text(summary, "ablation")
    if ablation_off:
        rows.append(
            (f"why the {VIRTUAL_LABEL}'s exponent differs (ablation)", "—", ablation_off, "")
        )
    if ablation:
        rows.append(
            (
                f"why the {VIRTUAL_LABEL}'s exponent differs (ablation)",
                "—",
                ablation["verdict"],
                "tables/ablation_exponent.csv; every variant: tables/ablation_exponent_all.csv",
            )
        )
    spread = summary.get("c_spread")
    spread_off = not_run_text(summary, "c_sensitivity")
    if spread_off:
        rows.append(("C of the simulation: spread over our choices", "—", spread_off, ""))
    if spread:
        rows.append(
            (
                "C of the simulation: headline choice and spread over choices (µs N^1/6)",
                "—",
                f"{spread['headline_C_us_N16']:.2f}; {spread['min_us_N16']:.2f} "
                f"({spread['min_choice']}) .. {spread['max_us_N16']:.2f} ({spread['max_choice']})",
                f"headline: {spread['headline_choice']}; one choice changed at a time "
                "(estimator, eta, sensor pair, amplitude half): tables/c_sensitivity.csv",
            )
        )
    return rows


def mechanism_markdown(summary: Mapping) -> list[str]:
    """Lines of ``summary.md`` for the mechanism study (none without it; one line when
    the config switched it off)."""
    study = summary.get("ssw_mechanisms")
    off = not_run_text(summary, "mechanisms")
    if off:
        return [
            "",
            "## Why are the measured SSW larger? (models, not data)",
            "",
            f"The mechanism study: {off}.",
        ]
    if not study:
        return []
    verdict = without_e_notation(study["verdict"], "unicode")
    lines = ["", "## Why are the measured SSW larger? (models, not data)", "", verdict]
    checks = study.get("lammps_check") or []
    if checks:
        worst_c = max(float(r["rel_diff_C"]) for r in checks)
        worst_trace = max(float(r["max_trace_diff_over_Fm"]) for r in checks)
        lines += [
            "",
            f"LAMMPS against our kernel in the frictionless 1D limit ({len(checks)} chain x "
            f"model cases): C within {power_of_ten(worst_c, 2, 'unicode')} relative, sensor "
            f"traces within {power_of_ten(worst_trace, 2, 'unicode')} F_m "
            "(tables/lammps_check.csv).",
        ]
    return lines
