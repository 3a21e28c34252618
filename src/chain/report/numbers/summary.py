"""The run's headline numbers beside the paper's: ``summary.json``.

Every number is computed from the run's tables and the closed forms of
:mod:`chain.physics.theory`, except the paper's own values in :data:`PAPER`, quoted as
printed. :func:`build_summary` gathers them into a JSON-ready dict and
:func:`write_summary_json` writes it; :mod:`chain.report.text.markdown` writes
``summary.md`` from it.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping

import numpy as np
import pandas as pd

from chain.analysis.rows import flag_counts, is_ok
from chain.analysis.selection import selection_counts, skipped_shots
from chain.analysis.ssw_fits import ssw_parity_table, ssw_resolution_table
from chain.analysis.ssw_speed import far_field_parity, separation_table
from chain.atomic import write_text_atomic
from chain.physics.theory import (
    EXACT_OVER_PAPER_BALLISTIC,
    HERTZ_TIME_CONSTANT,
    PAPER_TIME_CONSTANT,
    REDUCED_MASS_TIME_FACTOR,
    ballistic_constants,
)
from chain.report.naming import series_names
from chain.report.numbers.claim_rows import TOLERANCES
from chain.report.numbers.claims import dissipation_verdicts, energy_drift_within_paper
from chain.report.numbers.paper import PAPER, PAPER_BEADS

#: Significant digits of floats in summary.json.
JSON_DIGITS = 10


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


def table_section(tables: Mapping[str, pd.DataFrame], run: Mapping) -> dict:
    """A study's section of summary.json that is its tables' rows: name -> records (for
    a study without a verdict of its own; ``run``, the run's tables, unused).

    Parameters
    ----------
    tables : mapping
        Table name -> the study's table.
    run : mapping
        The run's own tables and main estimator.
    """
    return {name: _records(table) for name, table in tables.items()}


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
    ssw_speed: pd.DataFrame | None = None,
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
    ssw_speed : DataFrame, optional
        ``ssw_speed.csv`` (the SSW tracked along the chain).

    Returns
    -------
    dict
        The arguments' plain values, ``constants``, ``paper``, ``max_energy_drift``
        (largest relative drift of the conservative runs, None without any),
        ``energy_drift_by_model``, ``delay_fits`` and ``ssw_fits`` (the rows of the
        tables), ``flagged`` (per table and source: ``rows``, ``flagged`` = ok False,
        ``nan`` = ok but a NaN value; ssw counts the ``residual`` rows, the ones
        fitted and drawn), ``selection`` (kept/rejected shots per series, N and kind),
        ``experiment_tolerance``, ``attenuation``, the SSW keys of :func:`ssw_summary`
        and :func:`decisions`.
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
    summary = {
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
        **ssw_summary(ssw, ssw_fits, ssw_speed),
        # Only when shots were skipped, so that runs without any keep their bytes.
        **({"skipped_shots": skipped} if (skipped := skipped_shots(selection)) else {}),
    }
    return _number({**summary, **decisions(summary)})


def decisions(summary: Mapping) -> dict:
    """What the report decides about the run's numbers, once, for summary.md, the
    article and the figures to print (they never decide again).

    Parameters
    ----------
    summary : mapping
        The summary so far (:func:`build_summary`'s keys).

    Returns
    -------
    dict
        ``series_names`` (``{source: {model: name}}``, :mod:`chain.report.naming`),
        ``paper_beads`` (the paper's ``material`` and ``radius_m``, and ``same``: whether
        the run's beads are they, so that the paper's numbers compare),
        ``ballistic_factors`` (Eq. 6's contact time against the exact one:
        ``reduced_mass_time_factor``, ``hertz_time_constant``, ``paper_time_constant``
        and their product ``exact_over_paper``, :mod:`chain.physics.theory`) and
        ``verdicts``: the ``tolerances`` of :data:`chain.report.numbers.claim_rows.TOLERANCES`,
        ``dissipation`` (:func:`chain.report.numbers.claims.dissipation_verdicts`) and
        ``energy_drift_within_paper``. The claim table joins ``verdicts`` last
        (:func:`chain.report.numbers.claims.with_claims`).
    """
    series = [(r["source"], r["model"]) for r in [*summary["delay_fits"], *summary["ssw_fits"]]]
    same = summary["material"] == PAPER_BEADS["material"] and math.isclose(
        summary["radius_m"], PAPER_BEADS["radius_m"], rel_tol=1e-9
    )
    return {
        "series_names": series_names(series, summary["experiment_label"]),
        "paper_beads": {**PAPER_BEADS, "same": same},
        "ballistic_factors": {
            "reduced_mass_time_factor": REDUCED_MASS_TIME_FACTOR,
            "hertz_time_constant": HERTZ_TIME_CONSTANT,
            "paper_time_constant": PAPER_TIME_CONSTANT,
            "exact_over_paper": EXACT_OVER_PAPER_BALLISTIC,
        },
        "verdicts": {
            "tolerances": dict(TOLERANCES),
            "dissipation": dissipation_verdicts(summary),
            "energy_drift_within_paper": energy_drift_within_paper(summary["max_energy_drift"]),
        },
    }


def ssw_summary(
    ssw: pd.DataFrame | None, ssw_fits: pd.DataFrame, ssw_speed: pd.DataFrame | None
) -> dict:
    """The SSW keys of ``summary.json`` from ``ssw.csv``, ``ssw_fits.csv`` and
    ``ssw_speed.csv`` (``ssw`` and ``ssw_speed`` None when the run has none).

    Returns
    -------
    dict
        ``ssw_resolved``: per source, model, N and sensor, ``resolved`` (at least half
        the shots), ``n_resolved`` of ``n_total``
        (:func:`chain.analysis.ssw.ssw_resolution_table`); ``ssw_separation``: per
        model, N and wave, ``first_separated_contact`` (None if never),
        ``distance_beads`` from the collision point, ``speed_ratio`` to Eq. 5
        (:func:`chain.analysis.ssw_speed.separation_table`); ``ssw_parity_ratio``: per
        source and model, the SSW slope of N = 26 over N = 25 with ``ratio_err`` (None
        without both); ``ssw_far_field``: per source and model, SSW / F_m far from the
        collision point in the longest even and odd chain, with errors, and their ratio
        (:func:`chain.analysis.ssw_speed.far_field_parity`).
    """
    separation = [] if ssw_speed is None else _records(separation_table(ssw_speed))
    for row in separation:
        contact = row["first_separated_contact"]
        row["first_separated_contact"] = None if contact is None else int(contact)
    return {
        "ssw_resolved": [] if ssw is None else _records(ssw_resolution_table(ssw)),
        "ssw_separation": separation,
        "ssw_parity_ratio": _records(ssw_parity_table(ssw_fits)),
        "ssw_far_field": (
            []
            if ssw_speed is None or "ssw_over_Fm" not in ssw_speed
            else _records(far_field_parity(ssw_speed))
        ),
    }


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


def _residual_rows(ssw: pd.DataFrame | None) -> pd.DataFrame | None:
    """The SSW rows that are fitted and drawn (method ``residual``)."""
    if ssw is None or "method" not in ssw.columns:
        return ssw
    return ssw[ssw["method"] == "residual"]


def write_summary_json(summary: Mapping, json_path: str | os.PathLike) -> None:
    """Write ``summary`` (:func:`build_summary`) to ``json_path`` atomically, as
    :func:`summary_json`; ``summary.md`` is written from it by
    :func:`chain.report.text.markdown.write_summary_markdown`."""
    write_text_atomic(summary_json(summary), json_path)
