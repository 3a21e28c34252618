"""The crossing delay Delta of each collision shot, and its fit Delta = C F_m^(-1/6).

Delta compares times of flight (TOF) between the two sensors, never absolute times (a
lab never knows t = 0):

* LSTW: TOF(crossed) = T(S2, crossed) - T(S1, incident) in the collision shot;
* RSTW: TOF(crossed) = T(S1, crossed) - T(S2, incident), the mirror image;
* TOF(reference) = mean over the reference shots of the same (source, model, N,
  amplitude) of T(S2) - T(S1) of the single left-launched wave. The sensors sit
  symmetrically about the middle of the chain, so the same reference serves RSTW;

and Delta = TOF(crossed) - TOF(reference): negative when the crossed wave arrives early,
which is what the physics gives (Fig. 4 plots |Delta|). F_m is the incident amplitude
at the first sensor the wave meets (S1 for LSTW, S2 for RSTW).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from chain.analysis.regression import fit_fixed_exponent, fit_power_law
from chain.analysis.rows import is_ok
from chain.analysis.selection import GROUP as _GROUP
from chain.analysis.selection import apply_selection

#: Columns of :func:`delay_table`, in order (the last three are extras).
DELAY_COLUMNS = tuple(
    "source model N shot amplitude wave estimator F_m_N delay_us tof_crossed_us "
    "tof_reference_us n_reference ok reason F_m_stderr_N delay_stderr_us F_crossed_N".split()
)

#: Columns of :func:`delay_fit_table`, in order (after ``n_points``: extras).
DELAY_FIT_COLUMNS = tuple(
    "source model N estimator C_us_N16 C_stderr_us_N16 exponent exponent_stderr n_points "
    "prefactor_free_us prefactor_free_stderr_us rms_residual_us".split()
)

#: (first sensor met, sensor where the crossed wave is read) per wave.
_PATH = {"LSTW": ("S1", "S2"), "RSTW": ("S2", "S1")}


def reference_tofs(pulses: pd.DataFrame) -> pd.DataFrame:
    """S1 -> S2 time of flight of each ok reference shot, per estimator.

    Parameters
    ----------
    pulses : DataFrame
        ``pulses.csv`` rows (:func:`chain.analysis.pulse_rows.pulse_table`).

    Returns
    -------
    DataFrame
        ``source, model, N, amplitude, estimator, shot, tof_s, tof_var_s2`` (the variance
        from the two arrival-time standard errors).
    """
    ref = pulses[(pulses["role"] == "reference") & is_ok(pulses)]
    keys = [*_GROUP, "amplitude", "estimator", "shot"]
    columns = [*keys, "T_s", "T_stderr_s"]
    both = ref.loc[ref["sensor"] == "S1", columns].merge(
        ref.loc[ref["sensor"] == "S2", columns], on=keys, suffixes=("_1", "_2")
    )
    both["tof_s"] = both["T_s_2"] - both["T_s_1"]
    both["tof_var_s2"] = both["T_stderr_s_1"] ** 2 + both["T_stderr_s_2"] ** 2
    return both[[*keys, "tof_s", "tof_var_s2"]]


def delay_table(pulses: pd.DataFrame, selection: pd.DataFrame | None = None) -> pd.DataFrame:
    """Delta per collision shot, wave and estimator (the rows of ``delays.csv``).

    Parameters
    ----------
    pulses : DataFrame
        ``pulses.csv`` rows (:func:`chain.analysis.pulse_rows.pulse_table`).
    selection : DataFrame, optional
        Shot selection (``shot``, ``kept``); collision shots with ``kept`` False are
        dropped. None keeps every shot.

    Returns
    -------
    DataFrame
        Columns :data:`DELAY_COLUMNS`; ``delay_us`` = TOF(crossed) - TOF(reference), us.
        A row is ``ok`` False, with a reason, when a pulse it needs was flagged or no
        reference shot of its amplitude is usable.
    """
    pulses = apply_selection(pulses, selection)
    refs = reference_tofs(pulses)
    ref_stats = {
        key: (group["tof_s"].mean(), group["tof_var_s2"].sum() / len(group) ** 2, len(group))
        for key, group in refs.groupby([*_GROUP, "amplitude", "estimator"])
    }
    collision = pulses[pulses["kind"] == "collision"]
    # One reading of the flag: a row's ``ok`` below is a bool however the table was read.
    collision = collision.assign(ok=is_ok(collision))
    lookup = {
        (row.source, row.model, row.N, row.shot, row.estimator, row.sensor, row.role): row
        for row in collision.itertuples(index=False)
    }
    rows = []
    shots = collision[[*_GROUP, "shot", "amplitude", "estimator"]].drop_duplicates()
    for shot in shots.itertuples(index=False):
        key = (shot.source, shot.model, shot.N, shot.amplitude, shot.estimator)
        reference = ref_stats.get(key, (math.nan, math.nan, 0))
        where = (shot.source, shot.model, shot.N, shot.shot, shot.estimator)
        for wave, (first, crossed_at) in _PATH.items():
            incident = lookup.get((*where, first, "incident"))
            crossed = lookup.get((*where, crossed_at, "crossed"))
            rows.append(_delay_row(shot, wave, incident, crossed, reference))
    return pd.DataFrame(rows, columns=DELAY_COLUMNS)


def _delay_row(shot, wave: str, incident, crossed, reference: tuple) -> dict:
    """The ``delays.csv`` row of one wave of one collision shot.

    ``shot`` holds source, model, N, shot, amplitude and estimator; ``incident`` and
    ``crossed`` are the pulse rows the wave needs (None when absent); ``reference`` is
    (mean reference TOF s, its variance s^2, number of reference shots).
    """
    first, crossed_at = _PATH[wave]
    tof_ref, var_ref, n_ref = reference
    reasons = []
    if incident is None or not incident.ok:
        reasons.append(f"incident {wave} at {first}: {_why(incident)}")
    if crossed is None or not crossed.ok:
        reasons.append(f"crossed {wave} at {crossed_at}: {_why(crossed)}")
    if n_ref == 0:
        reasons.append("no usable reference shot of this amplitude")
    f_m = incident.F_m_N if incident is not None else math.nan
    tof = crossed.T_s - incident.T_s if incident is not None and crossed is not None else math.nan
    ok = not reasons
    return {
        **shot._asdict(),
        "wave": wave,
        "n_reference": n_ref,
        "F_m_N": f_m if ok else math.nan,
        "delay_us": (tof - tof_ref) * 1e6 if ok else math.nan,
        "tof_crossed_us": tof * 1e6 if ok else math.nan,
        "tof_reference_us": tof_ref * 1e6,
        "ok": ok,
        "reason": "; ".join(reasons),
        "F_m_stderr_N": incident.F_m_stderr_N if ok else math.nan,
        "delay_stderr_us": (
            math.sqrt(incident.T_stderr_s**2 + crossed.T_stderr_s**2 + var_ref) * 1e6
            if ok
            else math.nan
        ),
        "F_crossed_N": crossed.F_m_N if ok else math.nan,
    }


def _why(pulse) -> str:
    if pulse is None:
        return "no such pulse row"
    return str(pulse.reason) or "flagged"


def delay_fit_table(delays: pd.DataFrame) -> pd.DataFrame:
    """Fits of |Delta| against F_m (the rows of ``delay_fits.csv``, columns
    :data:`DELAY_FIT_COLUMNS`).

    Per (source, model, N, estimator), and pooled over N (``N = "pooled"``) per
    (source, model, estimator), from the ``ok`` rows of both waves:

    * ``C_us_N16``: least squares of |Delta| = C F_m^(-1/6), unweighted, standard error
      from the residual scatter (:func:`chain.analysis.regression.fit_fixed_exponent`);
    * ``exponent``, ``prefactor_free_us``: |Delta| = A F_m^p, straight line in log-log
      (:func:`chain.analysis.regression.fit_power_law`).

    Fewer than 2 points (3 for the free exponent) give NaN and ``n_points``. In a
    simulation with sensors placed symmetrically, LSTW and RSTW are mirror images and
    give equal points: they count twice, so the standard errors of simulated groups are
    about sqrt(2) too small; measured waves are independent.

    Parameters
    ----------
    delays : DataFrame
        ``delays.csv`` rows (:func:`delay_table`).
    """
    rows = []
    groups = [(keys, group) for keys, group in delays.groupby([*_GROUP, "estimator"], sort=True)]
    pooled = [
        ((s, m, "pooled", e), group)
        for (s, m, e), group in delays.groupby(["source", "model", "estimator"], sort=True)
    ]
    for (source, model, n_beads, estimator), group in groups + pooled:
        used = group[is_ok(group)]
        force = used["F_m_N"].to_numpy(dtype=float)
        delay = np.abs(used["delay_us"].to_numpy(dtype=float))
        fixed = fit_fixed_exponent(force, delay, -1.0 / 6.0)
        # ln |Delta| needs Delta != 0; an exact zero carries no exponent information.
        free = fit_power_law(force[delay > 0], delay[delay > 0])
        rows.append(
            {
                "source": source,
                "model": model,
                "N": n_beads if n_beads == "pooled" else int(n_beads),
                "estimator": estimator,
                "C_us_N16": fixed.coefficient,
                "C_stderr_us_N16": fixed.stderr,
                "exponent": free.exponent,
                "exponent_stderr": free.exponent_stderr,
                "n_points": fixed.n_points,
                "prefactor_free_us": free.prefactor,
                "prefactor_free_stderr_us": free.prefactor_stderr,
                "rms_residual_us": fixed.rms_residual,
            }
        )
    return pd.DataFrame(rows, columns=DELAY_FIT_COLUMNS)
