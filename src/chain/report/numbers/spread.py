"""Summary entries of the ablation of the virtual experiment and of the spread of C
(``summary.json`` keys ``ablation`` and ``c_spread``; their ``summary.md`` rows are in
:mod:`chain.report.text.markdown_studies`).

The numbers come from ``tables/ablation_exponent.csv`` (chain.studies.ablation_table) and
``tables/c_sensitivity.csv`` (chain.studies.c_sensitivity); nothing is computed here
but the selection of rows and the wording.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import pandas as pd

from chain.labels import VIRTUAL_LABEL
from chain.report.printed import fixed, plus_minus

#: Variants the verdict names when present: the reference shots' mismatch alone off,
#: and every imperfection off.
_CAUSE, _CLEAN = "no_reference_mismatch", "no_imperfections"


def _pooled(table: pd.DataFrame) -> pd.DataFrame:
    return table[table["N"].astype(str) == "pooled"]


def _records(table: pd.DataFrame) -> list[dict]:
    records = table.astype(object).where(table.notna(), None).to_dict(orient="records")
    return [
        {k: (v if not isinstance(v, float) or math.isfinite(v) else None) for k, v in r.items()}
        for r in records
    ]


def ablation_summary(tables: Mapping[str, pd.DataFrame], run: Mapping) -> dict:
    """The ablation's section of summary.json: ``{"verdict": one sentence with the
    numbers, "rows": the table's rows}``.

    Parameters
    ----------
    tables : mapping
        ``{"table": ablation_exponent.csv}``.
    run : mapping
        The run's ``delay_fits`` (its own virtual experiment: the configured variant)
        and main ``estimator``.
    """
    ablation, delay_fits, estimator = tables["table"], run["delay_fits"], run["estimator"]
    run = delay_fits[
        (delay_fits["source"] == "experiment")
        & (delay_fits["N"].astype(str) == "pooled")
        & (delay_fits["estimator"] == estimator)
    ]
    pooled = _pooled(ablation).set_index("variant")
    if run.empty or _CAUSE not in pooled.index or _CLEAN not in pooled.index:
        verdict = "not determined: the run lacks its virtual experiment or the variants "
        verdict += f"{_CAUSE} and {_CLEAN}"
        return {"verdict": verdict, "rows": _records(ablation)}
    r, cause, clean = run.iloc[0], pooled.loc[_CAUSE], pooled.loc[_CLEAN]
    sims = delay_fits[
        (delay_fits["source"] == "simulation")
        & (delay_fits["N"].astype(str) == "pooled")
        & (delay_fits["estimator"] == estimator)
    ]
    simulated = ", ".join(f"{m} {fixed(p, 3)}" for m, p in zip(sims["model"], sims["exponent"]))
    others = pooled.drop(index=[_CAUSE, _CLEAN], errors="ignore")
    verdict = (
        f"The {VIRTUAL_LABEL}'s steep free exponent "
        f"({plus_minus(r['exponent'], r['exponent_stderr'])}, chains pooled) comes from the "
        "random striker-speed mismatch of its reference shots, whose time of flight every "
        "collision of the same "
        "amplitude shares: with that mismatch alone off it is "
        f"{plus_minus(cause['exponent'], cause['exponent_stderr'])}, with every imperfection "
        f"off {plus_minus(clean['exponent'], clean['exponent_stderr'])} "
        f"(simulations: {simulated})"
    )
    if not others.empty:
        verdict += (
            f"; the other variants give {fixed(others['exponent'].min(), 3)} to "
            f"{fixed(others['exponent'].max(), 3)}"
        )
    verdict += "; a property of the protocol's statistics, not a model artefact."
    return {"verdict": verdict, "rows": _records(ablation)}


def c_spread_summary(tables: Mapping[str, pd.DataFrame], run: Mapping) -> dict:
    """The C sensitivity's section of summary.json: ``{"headline_choice", "min_us_N16",
    "max_us_N16", "rows"}`` from ``{"table": c_sensitivity.csv}``: the headline choice
    in words and the range of the pooled C over every choice whose chains all gave
    delays (``run``, the run's tables, unused)."""
    table = tables["table"]
    pooled = _pooled(table)
    head = pooled[pooled["headline"].astype(bool)].iloc[0]
    # Pooled rows missing a chain are not comparable with the headline.
    pooled = pooled[pooled["note"].fillna("") == ""]
    sim = table[table["headline"].astype(bool)]
    choice = (
        f"simulation, estimator {head['estimator']}, eta = {head['eta_us']:.3g} us, sensors "
        f"{head['sensors']}, all amplitudes, chains pooled: "
        f"C = {plus_minus(head['C'], head['C_stderr'])} us N^1/6"
    )
    low, high = pooled.loc[pooled["C"].idxmin()], pooled.loc[pooled["C"].idxmax()]
    return {
        "headline_choice": choice,
        "headline_C_us_N16": float(head["C"]),
        "min_us_N16": float(low["C"]),
        "min_choice": f"{low['choice']} = {low['value']}",
        "max_us_N16": float(high["C"]),
        "max_choice": f"{high['choice']} = {high['value']}",
        "n_headline_rows": len(sim),
        "rows": _records(table),
    }
