"""How much the fitted C of Delta = C F_m^(-1/6) depends on our choices.

Starting from the headline choice (the main estimator, the paper's Kuwabara-Kono time
eta, the configured sensors, every configured launch speed), one choice is changed at
a time and C and the free exponent are refitted, per chain and pooled:

* ``estimator``: each pulse estimator (fit_full, peak, fit_rise);
* ``eta_us``: eta = 0, the paper's, twice the paper's;
* ``sensors``: sensor pairs moved symmetrically by ``shift`` beads (positive: towards
  the collision point), the same shift on every chain;
* ``amplitudes``: the low and the high half of the launch speeds.

The shots are simulated with :func:`chain.apparatus.shots.simulate_shots` (once per eta
and chain, every sensor bead recorded) and analysed with
:func:`chain.analysis.pulse_rows.pulse_table` and :mod:`chain.analysis.recipe`, as in the
paper run. This module maps config keys; it reads no file and knows no Snakemake.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pandas as pd

from chain.analysis.pulse_rows import pulse_table
from chain.analysis.recipe import fit_pulses
from chain.traces import META_COLUMNS, sensor_column

#: Sensor shifts (beads, positive towards the collision point) besides the configured pair.
SENSOR_SHIFTS = (2, -2, -4)

#: Columns of :func:`c_sensitivity_table`, in order (after ``exponent_stderr``: extras).
C_SENSITIVITY_COLUMNS = tuple(
    "choice value N C C_stderr exponent exponent_stderr n_points estimator eta_us sensors "
    "amplitudes headline note".split()
)


def shifted_pairs(chains: Mapping[int, Sequence[int]], shift: int) -> dict[int, tuple[int, int]]:
    """Sensor pairs (S1 + shift, S2 - shift) per chain; None if one is not a valid pair."""
    pairs = {}
    for n, (s1, s2) in chains.items():
        pair = (s1 + shift, s2 - shift)
        if not 1 <= pair[0] < pair[1] <= n:
            return None
        pairs[n] = pair
    return pairs


def sensitivity_plan(config: Mapping, speeds_m_s: Sequence[float]) -> dict:
    """The choices of a schema-valid config (plain values, for rule params).

    Parameters
    ----------
    config : mapping
        A schema-valid config.
    speeds_m_s : sequence of float
        The run's launch speeds, m/s (:attr:`chain.pipeline.plan.run_plan.RunPlan.speeds`).

    Returns
    -------
    dict
        ``chains`` {N: [S1, S2]}, ``eta_s`` (0, the paper's = the largest model eta, or
        0.58e-6 if no model has one, and twice that), ``estimators``, ``main_estimator``,
        ``shifts`` (those valid on every chain), ``speeds_m_s`` (the run's launch speeds),
        ``simulation`` (the run's simulation section).
    """
    chains = {int(c["N"]): [int(b) for b in c["sensors"]] for c in config["chains"]}
    paper_eta = max([m["eta_s"] for m in config["models"]] + [0.0]) or 0.58e-6
    return {
        "chains": chains,
        "eta_s": [0.0, paper_eta, 2.0 * paper_eta],
        "estimators": list(config["analysis"]["estimators"]),
        "main_estimator": config["analysis"]["main_estimator"],
        "shifts": [s for s in SENSOR_SHIFTS if shifted_pairs(chains, s) is not None],
        "speeds_m_s": [float(v) for v in speeds_m_s],
        "simulation": dict(config["simulation"]),
    }


def _fits(pulses: pd.DataFrame, estimator: str, amplitudes=None) -> pd.DataFrame:
    """Delay fits of one estimator from the pulses of every chain (amplitude subset)."""
    rows = pulses[pulses["estimator"] == estimator]
    if amplitudes is not None:
        rows = rows[rows["amplitude"].isin(amplitudes)]
    return fit_pulses(rows)


def pair_pulses(traces: Mapping[int, pd.DataFrame], pairs, estimators) -> pd.DataFrame:
    """Pulse rows of every chain read at its pair of sensors.

    Parameters
    ----------
    traces : mapping
        N -> trace table recording (at least) the beads of ``pairs[N]``.
    pairs : mapping
        N -> (S1, S2).
    estimators : sequence of str
        Pulse estimators.
    """
    tables = []
    for n, table in traces.items():
        columns = [*META_COLUMNS, *(sensor_column(b) for b in pairs[n])]
        tables.append(pulse_table(table[columns], estimators=tuple(estimators)))
    return pd.concat(tables, ignore_index=True)


def c_sensitivity_table(
    traces: Mapping[float, Mapping[int, pd.DataFrame]], plan: Mapping, pulses_of=None
):
    """C and the free exponent for each choice (rows of ``c_sensitivity.csv``).

    Parameters
    ----------
    traces : mapping
        eta (s) -> {N -> simulated trace table with every sensor bead of the plan}.
    plan : mapping
        :func:`sensitivity_plan`.
    pulses_of : callable, optional
        ``pulses_of(eta_s, pairs, estimators)`` -> :func:`pair_pulses` rows of the
        traces at that eta (s) and those sensor pairs, with (at least) those
        estimators; by default computed here, as needed.

    Returns
    -------
    DataFrame
        Columns :data:`C_SENSITIVITY_COLUMNS`; C in us N^1/6. ``headline`` marks the rows
        of the headline choice (repeated under each choice it belongs to); ``note`` names
        chains without a usable delay (their pooled row holds the other chains only).
    """
    chains = {int(n): tuple(pair) for n, pair in plan["chains"].items()}
    main, eta_paper = plan["main_estimator"], plan["eta_s"][1]
    n_speeds = len(plan["speeds_m_s"])
    low, high = list(range(n_speeds // 2)), list(range(n_speeds // 2, n_speeds))
    if pulses_of is None:

        def pulses_of(eta, pairs, estimators):
            return pair_pulses(traces[eta], pairs, estimators)

    base = pulses_of(eta_paper, chains, plan["estimators"])
    cases = [
        ("estimator", e, _fits(base, e), e, eta_paper, chains, "all") for e in plan["estimators"]
    ]
    for eta in plan["eta_s"]:
        pulses = base if eta == eta_paper else pulses_of(eta, chains, [main])
        cases.append(("eta_us", f"{eta * 1e6:.3g}", _fits(pulses, main), main, eta, chains, "all"))
    for shift in [0, *plan["shifts"]]:
        pairs = shifted_pairs(chains, shift)
        pulses = base if shift == 0 else pulses_of(eta_paper, pairs, [main])
        value = f"shift {shift:+d} beads"
        cases.append(("sensors", value, _fits(pulses, main), main, eta_paper, pairs, "all"))
    for name, subset in (("all", None), ("low half", low), ("high half", high)):
        cases.append(("amplitudes", name, _fits(base, main, subset), main, eta_paper, chains, name))
    return pd.DataFrame(
        [row for case in cases for row in _rows(*case, chains, eta_paper, main)],
        columns=C_SENSITIVITY_COLUMNS,
    )


def _rows(choice, value, fits, estimator, eta, pairs, amplitudes, chains, eta_paper, main):
    headline = estimator == main and eta == eta_paper and pairs == chains and amplitudes == "all"
    sensors = "; ".join(f"N{n}: {list(pair)}" for n, pair in pairs.items())
    # A chain without a usable delay (e.g. sensors within a pulse width of the collision,
    # where incident and crossed pulses overlap) leaves the pooled fit to the others.
    empty = [str(f.N) for f in fits.itertuples(index=False) if f.N != "pooled" and not f.n_points]
    for fit in fits.itertuples(index=False):
        note = ""
        if empty:
            note = f"no usable delay on N = {', '.join(empty)}"
            note += "; pooled = the other chains only" if fit.N == "pooled" else ""
        yield {
            "choice": choice,
            "value": value,
            "N": fit.N,
            "C": fit.C_us_N16,
            "C_stderr": fit.C_stderr_us_N16,
            "exponent": fit.exponent,
            "exponent_stderr": fit.exponent_stderr,
            "n_points": fit.n_points,
            "estimator": estimator,
            "eta_us": eta * 1e6,
            "sensors": sensors,
            "amplitudes": amplitudes,
            "headline": headline,
            "note": note,
        }
