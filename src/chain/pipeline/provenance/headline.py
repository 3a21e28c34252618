"""Headline numbers of a run, compared with a committed reference (what CI checks).

From a run's ``summary.json``: C_bal, C and the free exponent per source, model, N and
estimator, the SSW slopes, the largest energy drift of the conservative runs. The
reference holds them with tolerances; it changes only in a reviewed commit saying why.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

from chain.analysis.delays import DELAY_FIT_COLUMNS
from chain.analysis.ssw_fits import SSW_FIT_COLUMNS
from chain.analysis.ssw_speed import SPEED_COLUMNS
from chain.analysis.ssw_track import TRACK_COLUMNS

#: The results contract (design.md) in results/<run_name>/: the figures (Fig. 2 with an
#: experiment), the contract columns of each table (more follow them), summary.json's keys.
CONTRACT_FIGURES = tuple(
    "fig1_setup fig3_simulation_traces fig4_delay_vs_force fig5_ssw_vs_force ssw_spacetime".split()
)
EXPERIMENT_FIGURES = ("fig2_experiment_traces",)
CONTRACT_TABLES = {
    "pulses.csv": (),
    "delays.csv": ("source", "model", "N", "F_m_N", "delay_us"),
    "delay_fits.csv": DELAY_FIT_COLUMNS[: DELAY_FIT_COLUMNS.index("n_points") + 1],
    "ssw.csv": ("source", "model", "N", "F_m_N", "ssw_N"),
    "ssw_fits.csv": SSW_FIT_COLUMNS[: SSW_FIT_COLUMNS.index("n_resolved") + 1],
    "ssw_track.csv": TRACK_COLUMNS[: TRACK_COLUMNS.index("separated") + 1],
    "ssw_speed.csv": SPEED_COLUMNS[: SPEED_COLUMNS.index("first_separated_contact") + 1],
}
SUMMARY_KEYS = tuple(
    "run_name constants paper max_energy_drift delay_fits ssw_fits ssw_resolved "
    "ssw_separation ssw_parity_ratio ssw_far_field".split()
)

#: Default tolerances, by kind of number and source: simulations may differ in the last
#: bits between CPUs (FMA, libm); the virtual experiment adds seeded noise on top.
DEFAULT_TOLERANCES = {
    "C_bal": {"relative": 1e-6},
    "C_us_N16/simulation": {"relative": 0.005},
    "C_us_N16/experiment": {"relative": 0.02},
    "exponent/simulation": {"absolute": 0.002},
    "exponent/experiment": {"absolute": 0.01},
    "ssw_slope/simulation": {"relative": 0.02},
    "ssw_slope/experiment": {"relative": 0.1},
    "max_energy_drift": {"maximum": 1e-9},
}


def missing_contract_files(run_folder: str | os.PathLike, experiment: bool = True) -> list[str]:
    """Contract files absent from ``run_folder`` (``results/<run_name>``), empty, or
    lacking their columns / keys; Fig. 2 too if the run has an ``experiment`` side."""
    import pandas as pd

    folder = Path(run_folder)
    problems = []
    for name in CONTRACT_FIGURES + (EXPERIMENT_FIGURES if experiment else ()):
        for path in (folder / "figures" / f"{name}.pdf", folder / "figures" / f"{name}.png"):
            if not path.is_file() or path.stat().st_size == 0:
                problems.append(f"{path}: missing or empty")
    for name, columns in CONTRACT_TABLES.items():
        path = folder / "tables" / name
        if not path.is_file():
            problems.append(f"{path}: missing")
            continue
        header = list(pd.read_csv(path, nrows=0).columns)
        if absent := [c for c in columns if c not in header]:
            problems.append(f"{path}: missing columns {absent}")
    for name in ("summary.json", "summary.md", "article.pdf"):
        if not (folder / name).is_file():
            problems.append(f"{folder / name}: missing")
    if (path := folder / "summary.json").is_file():
        summary = json.loads(path.read_text())
        if absent := [k for k in SUMMARY_KEYS if k not in summary]:
            problems.append(f"{path}: missing keys {absent}")
    return problems


def headline_numbers(summary: dict) -> dict[str, float]:
    """Flatten the headline numbers of ``summary`` (a run's parsed summary.json) into
    {name: value}, names such as ``C_us_N16/simulation/elastic/N=25/fit_full`` (a
    failing check reads on its own)."""
    numbers = {
        "C_bal/paper_form": summary["constants"]["C_bal_paper_us_N16"],
        "C_bal/exact_contact_time": summary["constants"]["C_bal_exact_us_N16"],
        "max_energy_drift": summary["max_energy_drift"],
    }
    for row in summary["delay_fits"]:
        key = f"{row['source']}/{row['model']}/N={row['N']}/{row['estimator']}"
        numbers[f"C_us_N16/{key}"] = row["C_us_N16"]
        numbers[f"exponent/{key}"] = row["exponent"]
    for row in summary["ssw_fits"]:
        method = row.get("method", "residual")
        numbers[f"ssw_slope/{row['source']}/{row['model']}/N={row['N']}/{method}"] = row["slope"]
    return numbers


def tolerance_for(name: str, tolerances: dict) -> dict:
    """The tolerance entry of ``tolerances`` that applies to headline number ``name``."""
    parts = name.split("/")
    for key in ("/".join(parts[:2]), parts[0]):
        if key in tolerances:
            return tolerances[key]
    raise KeyError(f"no tolerance for {name!r}")


def compare_with_reference(numbers: dict[str, float], reference: dict) -> list[str]:
    """Headline ``numbers`` (:func:`headline_numbers`) out of tolerance, missing or
    unexpected against ``reference`` (the parsed reference file: ``{"tolerances": {...},
    "values": {name: value}}``), one message each."""
    tolerances = reference.get("tolerances", DEFAULT_TOLERANCES)
    expected = reference["values"]
    failures = []
    for name in sorted(set(expected) - set(numbers)):
        failures.append(f"{name}: in the reference but not produced by this run")
    for name in sorted(set(numbers) - set(expected)):
        failures.append(f"{name}: produced by this run but not in the reference")
    for name in sorted(set(expected) & set(numbers)):
        value, target = numbers[name], expected[name]
        tolerance = tolerance_for(name, tolerances)
        if value is None or not math.isfinite(value):
            if target is None or (isinstance(target, float) and math.isnan(target)):
                continue
            failures.append(f"{name}: {value} is not a number (reference {target})")
        elif "maximum" in tolerance:
            if value > tolerance["maximum"]:
                failures.append(f"{name}: {value:.3g} exceeds the limit {tolerance['maximum']:.3g}")
        elif target is None:
            failures.append(f"{name}: {value:.6g} where the reference has no value")
        elif "relative" in tolerance:
            error = abs(value - target) / abs(target)
            if error > tolerance["relative"]:
                failures.append(
                    f"{name}: {value:.6g} differs from the reference {target:.6g} by "
                    f"{error:.2%} (tolerance {tolerance['relative']:.2%})"
                )
        elif abs(value - target) > tolerance["absolute"]:
            failures.append(
                f"{name}: {value:.6g} differs from the reference {target:.6g} by "
                f"{abs(value - target):.3g} (tolerance {tolerance['absolute']:.3g})"
            )
    return failures


def reference_from_summary(summary: dict, note: str) -> dict:
    """A reference file's content from a run's ``summary`` (parsed summary.json), with
    the default tolerances and a ``note`` on why it was (re)made."""
    numbers = headline_numbers(summary)
    return {
        "about": (
            "Headline numbers of the paper run checked by CI (hertzchain check). "
            "Change only in a reviewed commit that says why."
        ),
        "note": note,
        "run_name": summary["run_name"],
        "tolerances": DEFAULT_TOLERANCES,
        # A number the run could not give (a fit with no usable points) is JSON null.
        "values": {
            k: (None if v is None or not math.isfinite(v) else v)
            for k, v in sorted(numbers.items())
        },
    }
