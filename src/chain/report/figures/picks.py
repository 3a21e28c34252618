"""What the figures draw: look-ups in the tables, no drawing and no physics.

The figure modules ask here which amplitude, shot and rows to show (the representative
amplitude of Fig. 2/3, the shots the acceptance protocol kept, a shot's pulse times,
the SSW rows and fits drawn), so that their plot functions only draw.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from chain.analysis.rows import is_ok
from chain.traces import sensor_beads, sensor_column

#: SSW measurement drawn in Fig. 3 and Fig. 5 (chain.analysis.ssw: ``residual`` or ``peak``).
SSW_METHOD = "residual"


def main_method(table: pd.DataFrame) -> pd.DataFrame:
    """Rows of the SSW measurement drawn (``residual``), if the table has several."""
    if "method" in table.columns and (table["method"] == SSW_METHOD).any():
        return table[table["method"] == SSW_METHOD]
    return table


def is_pooled(column: pd.Series) -> pd.Series:
    """Which rows of a fit table's ``N`` column are the chains-pooled fit."""
    return column.astype(str) == "pooled"


def simulated_models(rows: pd.DataFrame) -> list:
    """Simulated models of ``rows`` in order of first appearance."""
    return list(dict.fromkeys(rows.loc[rows["source"] == "simulation", "model"]))


# ---- Fig. 2 / 3: which chain, amplitude and shot -----------------------------------


def split_by_chain(traces, source: str, model: str | None) -> dict[int, pd.DataFrame]:
    """Trace rows of ``source`` and ``model`` (None: the first model in the tables) by
    chain size N, in increasing N.

    Parameters
    ----------
    traces : DataFrame or sequence of DataFrames
        Trace tables.
    source : str
        ``simulation`` or ``experiment``.
    model : str or None
        Model (or series) name.
    """
    tables = [traces] if isinstance(traces, pd.DataFrame) else list(traces)
    chains: dict[int, pd.DataFrame] = {}
    for table in tables:
        table = table[table["source"] == source]
        if model is None and len(table):
            model = str(table["model"].iloc[0])
        table = table[table["model"] == model]
        for n, group in table.groupby("N", sort=True):
            group = group.dropna(axis=1, how="all")
            chains[int(n)] = group
    if not chains:
        raise ValueError(f"no {source} traces of model {model!r} to draw")
    return dict(sorted(chains.items()))


def _incident_forces(table, pulses, source, n, estimator) -> pd.Series:
    """Mean incident F_m at S1 per amplitude index, from ``pulses`` or else the peak of
    the S1 trace of the collision shots, N."""
    if pulses is not None and len(pulses):
        model = table["model"].iloc[0]
        rows = pulses[
            (pulses["source"] == source)
            & (pulses["model"] == model)
            & (pulses["N"].astype(str) == str(n))
            & (pulses["kind"] == "collision")
            & (pulses["sensor"] == "S1")
            & (pulses["role"] == "incident")
            & (pulses["estimator"] == estimator)
            & is_ok(pulses)
        ]
        if len(rows):
            return rows.groupby("amplitude")["F_m_N"].mean()
    first = sensor_column(sensor_beads(table)[0])
    collision = table[table["kind"] == "collision"]
    return collision.groupby("amplitude")[first].max()


def pick_amplitude(table, pulses, source, n, estimator, target_force, index, kept=None) -> int:
    """Amplitude index to draw: ``index``, else the one whose mean incident F_m at S1 is
    nearest ``target_force`` (N) on a log scale (the largest or smallest if the target
    is out of range), among the amplitudes in ``kept`` when given.

    Parameters
    ----------
    table : DataFrame
        Trace rows of one chain.
    pulses : DataFrame or None
        ``pulses.csv`` (without it: the peak of the S1 trace).
    source : str
        ``simulation`` or ``experiment``.
    n : int
        Number of beads.
    estimator : str
        Estimator whose F_m is used.
    target_force : float
        Wanted incident F_m, N.
    index : int or None
        Amplitude index that overrides the force.
    kept : set, optional
        Amplitude indices allowed (those with a kept collision).
    """
    if index is not None:
        return int(index)
    forces = _incident_forces(table, pulses, source, n, estimator)
    forces = forces[np.isfinite(forces) & (forces > 0)]
    if kept is not None and forces.index.isin(kept).any():
        forces = forces[forces.index.isin(kept)]
    if forces.empty:
        raise ValueError(f"N = {n}: no {source} amplitude with a positive incident F_m")
    return int((np.log(forces / target_force)).abs().idxmin())


def pulse_times(pulses, shot_meta, sensor: str, estimator: str) -> dict:
    """``{role: (T_s, tau_s, F_m_N)}`` of one shot's usable pulses at ``sensor``
    (roles ``incident``, ``crossed``, ``reference``); s, s, N."""
    if pulses is None or not len(pulses):
        return {}
    rows = pulses[
        (pulses["source"] == shot_meta["source"])
        & (pulses["model"] == shot_meta["model"])
        & (pulses["N"].astype(str) == str(shot_meta["N"]))
        & (pulses["shot"] == shot_meta["shot"])
        & (pulses["sensor"] == sensor)
        & (pulses["estimator"] == estimator)
        & is_ok(pulses)
    ]
    return {row.role: (row.T_s, row.tau_s, row.F_m_N) for row in rows.itertuples()}


def split_index(time, force, times) -> int | None:
    """Index of the minimum between the incident and the crossed pulse, or None.

    Parameters
    ----------
    time, force : ndarray
        One sensor's trace of a collision shot, s and N.
    times : dict
        Its :func:`pulse_times` (without the two pulses: the two highest peaks).
    """
    if "incident" in times and "crossed" in times:
        lo, hi = np.searchsorted(time, [times["incident"][0], times["crossed"][0]])
    else:
        from scipy.signal import find_peaks  # only without a pulse table: keep jobs light

        peaks, _ = find_peaks(force, prominence=0.3 * np.max(force))
        if len(peaks) < 2:
            return None
        lo, hi = peaks[0], peaks[1]
    if hi <= lo + 1:
        return None
    return int(lo + np.argmin(force[lo:hi]))


def kept_shots(selection, table) -> set | None:
    """Shots (collision and reference) of ``table``'s chain that the acceptance protocol
    kept (``experiment/selection.csv``); None without a selection."""
    if selection is None or not len(selection):
        return None
    meta = table.iloc[0]
    rows = selection[
        (selection["model"] == meta["model"])
        & (selection["N"].astype(str) == str(meta["N"]))
        & is_ok(selection, "kept")
    ]
    if "source" in selection.columns:
        rows = rows[rows["source"] == meta["source"]]
    return set(rows["shot"])


def kept_amplitudes(table, kept) -> set:
    """Amplitude indices of ``table`` with at least one collision shot in ``kept``."""
    collisions = table[(table["kind"] == "collision") & table["shot"].isin(kept)]
    return set(collisions["amplitude"])


def first_shot(shots, kind: str, kept=None):
    """Rows of the first shot of ``kind`` (among ``kept`` when it holds one), or None."""
    rows = shots[shots["kind"] == kind]
    if kept is not None and rows["shot"].isin(kept).any():
        rows = rows[rows["shot"].isin(kept)]
    if rows.empty:
        return None
    return rows[rows["shot"] == rows["shot"].min()]


def ssw_marker(ssw, meta, sensor: str) -> tuple[float, float] | None:
    """(time µs, amplitude N) of the SSW of one shot at ``sensor`` where it is resolved
    as a separate wave (``resolved``, else ``ok`` in older tables), or None."""
    if ssw is None or not len(ssw):
        return None
    ssw = main_method(ssw)
    rows = ssw[
        (ssw["source"] == meta["source"])
        & (ssw["model"] == meta["model"])
        & (ssw["N"].astype(str) == str(meta["N"]))
        & (ssw["shot"] == meta["shot"])
        & (ssw["sensor"] == sensor)
        & is_ok(ssw)
    ]
    if "resolved" in rows.columns:
        rows = rows[rows["resolved"].astype(bool)]
    if len(rows) and np.isfinite(rows["ssw_time_us"].iloc[0]):
        return (float(rows["ssw_time_us"].iloc[0]), float(rows["ssw_N"].iloc[0]))
    return None


# ---- Fig. 4 / 5: which fits ----------------------------------------------------------


def experiment_chain_fits(fits, estimator: str) -> dict:
    """``{(model, N): (C, C stderr)}`` of the per-chain experiment delay fits, µs N^(1/6)."""
    per_chain = {}
    if fits is not None and len(fits):
        for fit in fits[(fits["estimator"] == estimator) & ~is_pooled(fits["N"])].itertuples():
            if fit.source == "experiment" and np.isfinite(fit.C_us_N16):
                per_chain[(fit.model, int(fit.N))] = (fit.C_us_N16, fit.C_stderr_us_N16)
    return per_chain


def pooled_fits(fits, estimator: str):
    """Rows of ``delay_fits.csv`` of ``estimator`` with chains pooled, finite C."""
    chosen = fits[(fits["estimator"] == estimator) & is_pooled(fits["N"])]
    return [fit for fit in chosen.itertuples() if np.isfinite(fit.C_us_N16)]


def representative_shots(table, pulses, selection, *, source, n, estimator, force, index):
    """The collision and reference shot of one chain drawn in Fig. 2/3 (rows, or None).

    The amplitude is :func:`pick_amplitude`'s (whose parameters it takes, ``force``
    its ``target_force``, N), among the amplitudes with a collision the acceptance
    protocol kept when ``selection`` (``experiment/selection.csv`` or None) is given;
    the shot of each kind is the first one kept (the first one without a selection).
    """
    kept = kept_shots(selection, table)
    amplitude = pick_amplitude(
        table,
        pulses,
        source,
        n,
        estimator,
        force,
        index,
        None if kept is None else kept_amplitudes(table, kept),
    )
    shots = table[table["amplitude"] == amplitude]
    if shots.empty:
        raise ValueError(f"N = {n}: no shot of amplitude index {amplitude}")
    return first_shot(shots, "collision", kept), first_shot(shots, "reference", kept)
